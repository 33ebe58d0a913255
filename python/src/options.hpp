// Python keyword arguments made from a library options struct's own
// description (texel/option_spec.hpp), as the CLI's flags are
// (apps/texel/option_flags.hpp): each described option is a keyword of the
// same name as the struct's member, checked with the library's rule; the
// description itself is readable from Python (defaults included), and the
// package's stubs are tested against it (tests/python/test_options.py).
#pragma once

#include <set>
#include <string>
#include <type_traits>

#include <pybind11/pybind11.h>

#include "texel/error.hpp"
#include "texel/option_spec.hpp"

namespace texel::python {

namespace py = pybind11;

/// Sets the options named in `kwargs` (every key must be a described
/// option: InvalidArgument naming the allowed ones otherwise).
template <class Options>
void set_options(Options& options, const py::kwargs& kwargs, const std::string& what) {
  std::set<std::string> known;
  std::string names;
  visit_options(options, [&](auto& member, const OptionSpec& spec) {
    using T = std::remove_cvref_t<decltype(member)>;
    const std::string key(spec.key);
    known.insert(key);
    names += (names.empty() ? "" : ", ") + key;
    if (!kwargs.contains(key)) return;
    const py::handle v = kwargs[key.c_str()];
    if constexpr (std::is_same_v<T, bool>) {
      if (!py::isinstance<py::bool_>(v)) throw InvalidArgument(what + ": " + key + " must be True or False");
      member = v.cast<bool>();
    } else if constexpr (std::is_enum_v<T>) {
      if (!py::isinstance<py::str>(v)) throw InvalidArgument(what + ": " + key + " must be one of: " + allowed_text(spec));
      member = static_cast<T>(parse_option_choice(spec, v.cast<std::string>(), key));
    } else {
      if (py::isinstance<py::bool_>(v) || !(py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v)))
        throw InvalidArgument(what + ": " + key + " must be a number");
      const double d = v.cast<double>();
      check_option_value(spec, d, key);
      if constexpr (std::is_integral_v<T>) {
        if (d != static_cast<double>(static_cast<long long>(d)))
          throw InvalidArgument(what + ": " + key + " must be a whole number");
        member = static_cast<T>(d);
      } else {
        member = static_cast<T>(d);
      }
    }
  });
  for (const auto& item : kwargs) {
    const std::string key = py::str(item.first);
    if (!known.contains(key)) throw InvalidArgument(what + ": unknown option '" + key + "'; allowed: " + names);
  }
}

/// The description as Python sees it: one dict per option (key, flag,
/// help, default, default_text, and min/max/exclusive or choices) in the
/// front doors' order, the defaults those of `defaults`.
template <class Options>
py::list options_list(const Options& defaults) {
  py::list out;
  visit_options(defaults, [&](const auto& v, const OptionSpec& spec) {
    using T = std::remove_cvref_t<decltype(v)>;
    py::dict d;
    d["key"] = std::string(spec.key);
    d["flag"] = spec.flag.empty() ? std::string() : "--" + std::string(spec.flag);
    d["help"] = std::string(spec.help);
    d["default_text"] = option_default_text(v, spec);
    if constexpr (std::is_enum_v<T>) {
      d["default"] = std::string(choice_name(spec.choices, static_cast<int>(v)));
      py::list choices;
      for (const auto& c : spec.choices) choices.append(std::string(c.name));
      d["choices"] = choices;
    } else {
      if constexpr (is_optional_option<T>) {
        if (v) {
          if constexpr (is_quantity_option<typename T::value_type>)
            d["default"] = v->value();
          else
            d["default"] = *v;
        } else {
          d["default"] = py::none();
        }
      } else if constexpr (is_quantity_option<T>) {
        d["default"] = v.value();
      } else {
        d["default"] = v;
      }
      if constexpr (!std::is_same_v<T, bool>) {
        d["min"] = spec.min;
        d["max"] = spec.max;
        d["min_exclusive"] = spec.min_exclusive;
        d["max_exclusive"] = spec.max_exclusive;
      }
    }
    out.append(d);
  });
  return out;
}

}  // namespace texel::python
