#include "texel/option_spec.hpp"

#include <cmath>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel {

std::string option_number_text(double v) { return detail::num(v); }

std::string allowed_text(const OptionSpec& spec) {
  if (!spec.choices.empty()) {
    std::string list;
    for (const auto& c : spec.choices) list += (list.empty() ? "" : ", ") + std::string(c.name);
    return list;
  }
  const bool low = std::isfinite(spec.min), high = std::isfinite(spec.max);
  const std::string lo = detail::num(spec.min), hi = detail::num(spec.max);
  if (low && high && !spec.min_exclusive && !spec.max_exclusive) return lo + " … " + hi;
  const std::string from = low ? (spec.min_exclusive ? "above " : "at least ") + lo : "";
  const std::string to = high ? (spec.max_exclusive ? "below " : "at most ") + hi : "";
  return from + (low && high ? " and " : "") + to;
}

void check_option_value(const OptionSpec& spec, double v, std::string_view name) {
  const bool inside = std::isfinite(v) && (spec.min_exclusive ? v > spec.min : v >= spec.min) &&
                      (spec.max_exclusive ? v < spec.max : v <= spec.max);
  if (!inside) {
    const std::string allowed = allowed_text(spec);
    throw InvalidArgument(std::string(name) + " is " + detail::num(v) +
                          "; allowed: " + (allowed.empty() ? "a finite number" : allowed));
  }
}

int parse_option_choice(const OptionSpec& spec, std::string_view text, std::string_view name) {
  for (const auto& c : spec.choices)
    if (c.name == text) return c.value;
  throw InvalidArgument(std::string(name) + " is '" + std::string(text) + "'; allowed: " + allowed_text(spec));
}

}  // namespace texel
