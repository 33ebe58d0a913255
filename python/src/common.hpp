// Shared helpers of the Python binding: numpy arrays that own C++ vectors
// (zero copy), dtype names, and the per-area registration functions that
// module.cpp calls. Everything here converts; nothing computes.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/store.hpp"
#include "texel/signal.hpp"
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
void register_signal(py::module_& m);
void register_codec(py::module_& m);
void register_spectrum(py::module_& m);
void register_interchange(py::module_& m);
void register_player(py::module_& m);
void register_surface2d(py::module_& m);
void register_encode2d(py::module_& m);
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

/// A session database held open until close() (texel.Store): Python code
/// decides when the file is let go, not the garbage collector. A
/// texel.experiment.Session shares it.
struct StoreHandle {
  StoreHandle(experiment::Store s, experiment::StoreMode m) : store(std::move(s)), mode(m) {}
  std::optional<experiment::Store> store;
  experiment::StoreMode mode;
  experiment::Store& get() {
    if (!store) throw InvalidArgument("the store is closed");
    return *store;
  }
  /// Closes the connection. A read-only SQLite connection cannot remove the
  /// -wal/-shm files a WAL database keeps beside it (only the last
  /// read-write connection to close does), so after a read a writable
  /// database is opened read-write once and closed: if nothing else has it
  /// open, SQLite checkpoints and removes them. Nothing is written (the file
  /// was validated as a current-schema database when it was opened).
  void close() {
    if (!store) return;
    const std::string path = store->path();
    store.reset();
    if (mode != experiment::StoreMode::read_only) return;
    try {
      (void)experiment::Store::open(path, experiment::StoreMode::read_write);
    } catch (const Error&) {  // write-protected or in use: the files stay, as SQLite wants
    }
  }
};

// Declarations shared between areas (defined in experiment.cpp).

/// Trial rows as a list of dicts, one key per trial_columns() name.
py::list rows_records(const std::vector<experiment::TrialRow>& rows);
/// A session's record as a dict (id, participant, protocol, status, …).
py::dict session_dict(const experiment::SessionInfo& s);

void register_session(py::module_& m);

// Declarations shared between areas (defined in signal.cpp).

std::vector<std::byte> bytes_of(const py::bytes& b);
py::bytes to_bytes(std::span<const std::byte> v);
/// A str or os.PathLike (anything else is data: an array, bytes).
bool is_path(const py::handle& source);
std::string path_of(const py::handle& source);
/// The library options of a load_signal()/encode() call (texel/signal.hpp),
/// from this package's keywords.
SignalOptions signal_options(const py::object& device, std::optional<double> spacing_mm, const py::object& region,
                             std::optional<double> swipe_speed, const py::object& channel, std::size_t max_samples);
/// A path (codec::load_signal: every format, bitstreams too) or an array
/// (read as the .npy file that holds it) as a signal. Releases the GIL while reading.
texel::Signal signal_of(const py::handle& source, const SignalOptions& options);

}  // namespace texel::python
