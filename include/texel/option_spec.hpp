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
#include <span>
#include <string>
#include <string_view>

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
