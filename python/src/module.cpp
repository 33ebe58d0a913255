// texel._texel: the extension module behind the `texel` package. This file
// only defines the exception classes and calls each area's registration;
// python/texel/__init__.py re-exports everything.
//
// Errors: texel::Error and its families become texel.Error and subclasses
// carrying the engine's message unchanged. InvalidArgument is also a
// ValueError and IoError also an OSError, so ordinary Python handlers
// (`except ValueError`, `except OSError`) catch them too.
#include <exception>
#include <string_view>
#include <utility>

#include "common.hpp"
#include "options.hpp"
#include "texel/codec.hpp"
#include "texel/error.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/texture.hpp"

namespace texel::python {
namespace {

PyObject* new_exception(py::module_& m, const char* name, const char* doc, PyObject* bases) {
  const std::string qualified = std::string("texel.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases, nullptr);
  if (!type) throw py::error_already_set();
  m.add_object(name, py::handle(type));  // the module keeps a reference
  return type;
}

py::ssize_t as_ssize(std::size_t n) { return static_cast<py::ssize_t>(n); }

// The exception types, created once at import (the translator must be a
// plain function, so it finds them here).
PyObject* error_type = nullptr;
PyObject* invalid_type = nullptr;
PyObject* format_type = nullptr;
PyObject* io_type = nullptr;

void translate(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const texel::FieldError& e) {
    // The library's option field, spelled as this package's keyword.
    static const std::pair<std::string_view, std::string_view> keywords[] = {{"spacing", "spacing_mm"},
                                                                             {"swipe_speed", "swipe_speed_mm_s"}};
    std::string field = e.field();
    for (const auto& [f, k] : keywords)
      if (f == field) field = k;
    PyErr_SetString(invalid_type, (field + " " + e.detail()).c_str());
  } catch (const texel::InvalidArgument& e) {
    PyErr_SetString(invalid_type, e.what());
  } catch (const texel::FormatError& e) {
    PyErr_SetString(format_type, e.what());
  } catch (const texel::IoError& e) {
    PyErr_SetString(io_type, e.what());
  } catch (const texel::Error& e) {
    PyErr_SetString(error_type, e.what());
  }
}

}  // namespace

py::array bytes_as_numpy(std::vector<std::byte>&& bytes, const py::dtype& dtype) {
  auto* owned = new std::vector<std::byte>(std::move(bytes));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<std::byte>*>(p); });
  const auto item = static_cast<std::size_t>(dtype.itemsize());
  return py::array(dtype, {as_ssize(owned->size() / item)}, {as_ssize(item)}, owned->data(), owner);
}

std::vector<double> as_doubles(const py::handle& values, const char* name) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!a) throw py::type_error(std::string(name) + " must be a 1-D array of numbers");
  if (a.ndim() != 1)
    throw py::value_error(std::string(name) + " must be 1-D; it has " + std::to_string(a.ndim()) + " dimensions");
  return {a.data(), a.data() + a.size()};
}

}  // namespace texel::python

PYBIND11_MODULE(_texel, m) {
  namespace py = pybind11;
  using namespace texel::python;
  // The signatures are the pure-Python layer's (python/texel/__init__.py,
  // from the stubs), so docstrings start with the text, not a signature line.
  py::options options;
  options.disable_function_signatures();
  m.doc() = "Texel: multi-scale virtual haptic textures (the C++ engine's Python binding).";
  m.attr("__version__") = TEXEL_VERSION;

  error_type = new_exception(m, "Error", "Base of every error the Texel engine raises on purpose.", PyExc_RuntimeError);
  invalid_type = new_exception(m, "InvalidArgument", "A parameter outside its allowed range or set (also a ValueError).",
                               py::make_tuple(py::handle(error_type), py::handle(PyExc_ValueError)).release().ptr());
  format_type = new_exception(m, "FormatError", "A file or byte string that does not parse or validate.", error_type);
  io_type =
      new_exception(m, "IoError", "An operating-system level failure: unreadable input, unwritable output (also an OSError).",
                    py::make_tuple(py::handle(error_type), py::handle(PyExc_OSError)).release().ptr());
  py::register_exception_translator(&translate);

  register_render(m);
  register_signal(m);
  register_codec(m);
  register_encode2d(m);
  register_spectrum(m);
  register_interchange(m);
  register_player(m);
  register_surface2d(m);
  register_experiment(m);
  register_session(m);
  // The options each operation takes, as the library describes them once
  // (texel/option_spec.hpp): what the keyword arguments' defaults, the CLI's
  // flags and C's *_default() structs are made from and tested against.
  m.def(
      "options",
      [](const std::string& name) -> py::list {
        if (name == "render") return texel::python::options_list(texel::TexelSpec{});
        if (name == "encode") return texel::python::options_list(texel::codec::EncoderConfig{});
        if (name == "swipe") return texel::python::options_list(texel::SwipeOptions{});
        if (name == "play") return texel::python::options_list(texel::play_options());
        if (name == "player") return texel::python::options_list(texel::PlayerConfig{});
        if (name == "path_2d") return texel::python::options_list(texel::Path2DConfig{});
        throw texel::InvalidArgument("options: '" + name +
                                     "' is not an operation; allowed: render, encode, swipe, play, player, "
                                     "path_2d (analysis: texel.experiment.analysis_options())");
      },
      py::arg("name"),
      "The options of an operation as the library describes them: one dict per option with key (the\n"
      "keyword), flag (the CLI's), help, default, default_text and range or choices. name: render (the\n"
      "texture of render()/document()), encode, swipe, play, player (a real-time Player's) or path_2d.");
}
