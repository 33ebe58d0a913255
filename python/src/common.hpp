// Shared helpers of the Python binding: numpy arrays that own C++ vectors
// (zero copy), dtype names, and the per-area registration functions that
// module.cpp calls. Everything here converts; nothing computes.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/texture.hpp"

namespace texel::python {

namespace py = pybind11;

/// A 1-D numpy array that takes ownership of `v` (no copy): the vector moves
/// to the heap and a capsule frees it when the array is collected.
template <class T>
py::array_t<T> to_numpy(std::vector<T>&& v) {
  auto* owned = new std::vector<T>(std::move(v));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>({static_cast<py::ssize_t>(owned->size())}, {static_cast<py::ssize_t>(sizeof(T))}, owned->data(), owner);
}

/// Device-native bytes viewed as a numpy array of `dtype` ("<u2", "u1",
/// "<f4", "<f8"), owning the byte vector.
py::array bytes_as_numpy(std::vector<std::byte>&& bytes, const py::dtype& dtype);

/// A contiguous float64 copy of any 1-D array-like (numbers in [0, 1]).
std::vector<double> as_doubles(const py::handle& values, const char* name);

void register_render(py::module_& m);
void register_codec(py::module_& m);
void register_player(py::module_& m);
void register_experiment(py::module_& m);

// Declarations shared between areas (defined in render.cpp).

/// A device profile from a name/path or a DeviceProfile object, with the
/// optional grid overrides (library: with_grid).
DeviceProfile device_of(const py::handle& device, std::optional<double> length_mm, std::optional<double> spacing_mm);
/// A TexelSpec as a dict whose keys are the keyword arguments of texel.render.
py::dict spec_dict(const TexelSpec& spec);
/// Renders a prepared document's whole map: dtype "native" (the device
/// format), "float64" (amplitudes), "uint16", "uint8" or "float32". The GIL
/// is released while rendering.
py::array render_document_array(const Document& doc, const std::string& dtype);

}  // namespace texel::python
