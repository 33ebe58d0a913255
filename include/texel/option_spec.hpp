// An option of a library options struct, described once. A struct that
// offers its options to the front doors has a `visit_options(Struct&, Visit)`
// beside it that calls `visit(member, OptionSpec{…})` for each option, in
// the order the front doors list them; the CLI's flags and help, Python's
// keyword arguments and the checks of their values are all made from that
// one list (apps/texel/option_flags.hpp, python/src/options.hpp), and the
// default each shows is the default-constructed struct's value — so a
// default or a range changes in one place (docs/contributing.md).
//
// The library still validates the struct itself (a C++ caller fills it
// directly), from the same description (check_option_value), so `min`/`max`
// here are that rule; the front doors refuse a value outside it before
// calling, naming the option their own way.
#pragma once

#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "texel/units.hpp"

namespace texel {

/// One spelling of an enumerated option and the value it stands for.
struct OptionChoice {
  std::string_view name;
  int value;
};

/// What a front door needs to offer one option.
struct OptionSpec {
  std::string_view key;   ///< the library's and Python's name: "reversals_k"
  std::string_view flag;  ///< the CLI's long flag without "--": "reversals"
  std::string_view help;  ///< one sentence (an enumeration's names its spellings); each front door appends the default
  double min = -std::numeric_limits<double>::infinity();  ///< numbers: the least value
  double max = std::numeric_limits<double>::infinity();   ///< numbers: the greatest value
  bool min_exclusive = false;                             ///< min itself is refused
  bool max_exclusive = false;                             ///< max itself is refused
  std::span<const OptionChoice> choices = {};             ///< enumerations: every spelling, in order
};

/// The spelling of `value` among `choices` ("" if none).
constexpr std::string_view choice_name(std::span<const OptionChoice> choices, int value) {
  for (const auto& c : choices)
    if (c.value == value) return c.name;
  return {};
}

namespace detail {
template <class T>
struct is_quantity : std::false_type {};
template <class Tag>
struct is_quantity<Quantity<Tag>> : std::true_type {};
template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};
}  // namespace detail

/// A described member's type is a typed unit (Millimetres, Hertz, …): the
/// front doors offer it as a number in that unit (the key names the unit).
template <class T>
inline constexpr bool is_quantity_option = detail::is_quantity<std::remove_cvref_t<T>>::value;
/// A described member is std::optional<…>: "none" by default (the front
/// doors: no flag, Python None, C 0).
template <class T>
inline constexpr bool is_optional_option = detail::is_optional<std::remove_cvref_t<T>>::value;

/// A number as the front doors show it: the shortest text that reads back
/// exactly ("0.25", "48000", "1e-06").
std::string option_number_text(double v);

/// The value as a front door shows it as a default: the spelling of an
/// enumeration, "on"/"off", the shortest exact number, "none" for an empty
/// optional.
template <class T>
std::string option_default_text(const T& v, const OptionSpec& spec) {
  if constexpr (is_optional_option<T>)
    return v ? option_default_text(*v, spec) : std::string("none");
  else if constexpr (std::is_enum_v<T>)
    return std::string(choice_name(spec.choices, static_cast<int>(v)));
  else if constexpr (std::is_same_v<T, bool>)
    return v ? "on" : "off";
  else if constexpr (is_quantity_option<T>)
    return option_number_text(v.value());
  else if constexpr (std::is_integral_v<T>)
    return std::to_string(v);
  else
    return option_number_text(static_cast<double>(v));
}

/// One described option as documentation reads it: the spec and the default
/// in words (option_default_text of the described struct's default).
struct OptionDoc {
  OptionSpec spec;
  std::string default_text;
};

/// Every option `visit_options(defaults, …)` describes, with the defaults'
/// values, in the front doors' order.
template <class Options>
std::vector<OptionDoc> describe_options(const Options& defaults) {
  std::vector<OptionDoc> out;
  visit_options(defaults, [&](const auto& v, const OptionSpec& spec) { out.push_back({spec, option_default_text(v, spec)}); });
  return out;
}

/// The help of the described option `key` with its default appended, as a
/// front door prints it: "Texel length, mm [0.25]". Throws std::logic_error
/// for a key the description does not have (a front door asking for an
/// option the library does not describe is a programming error).
template <class Options>
std::string option_help(const Options& defaults, std::string_view key) {
  for (const auto& d : describe_options(defaults))
    if (d.spec.key == key) return std::string(d.spec.help) + " [" + d.default_text + "]";
  throw std::logic_error("no described option '" + std::string(key) + "'");
}

/// The default of the described option `key` in `defaults`, as a number
/// (enumerations: their value; Quantity: its value(); optional: NaN when
/// empty). Throws std::logic_error for an unknown key.
template <class Options>
double option_default(const Options& defaults, std::string_view key) {
  double out = 0.0;
  bool found = false;
  visit_options(defaults, [&](const auto& v, const OptionSpec& spec) {
    if (spec.key != key) return;
    found = true;
    using T = std::remove_cvref_t<decltype(v)>;
    if constexpr (is_optional_option<T>) {
      out = std::numeric_limits<double>::quiet_NaN();
      if (v) {
        if constexpr (is_quantity_option<typename T::value_type>)
          out = v->value();
        else
          out = static_cast<double>(*v);
      }
    } else if constexpr (is_quantity_option<T>) {
      out = v.value();
    } else {
      out = static_cast<double>(v);
    }
  });
  if (!found) throw std::logic_error("no described option '" + std::string(key) + "'");
  return out;
}

/// The allowed values in words: "1 … 1000", "above 0 and below 1", "at least
/// 0", "below 1", "png, svg"; "" when any value is allowed.
std::string allowed_text(const OptionSpec& spec);

/// Throws InvalidArgument "<name> is <v>; allowed: <allowed_text>" unless `v`
/// is finite and inside the spec's range; `name` is how the front door
/// spells the option ("--level", "level").
void check_option_value(const OptionSpec& spec, double v, std::string_view name);

/// The value `text` spells among the spec's choices; throws InvalidArgument
/// "<name> is '<text>'; allowed: png, svg" otherwise.
int parse_option_choice(const OptionSpec& spec, std::string_view text, std::string_view name);

}  // namespace texel
