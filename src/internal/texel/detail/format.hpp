// Small formatting helpers for error messages and text output.
#pragma once

#include <charconv>
#include <cmath>
#include <string>
#include <string_view>

namespace texel::detail {

/// Shortest round-trip decimal form of a double ("0.25", "1e-05", "nan").
inline std::string num(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[32];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

/// Fixed notation with `digits` decimals.
inline std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return num(v);
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, digits);
  return std::string(buf, res.ptr);
}

}  // namespace texel::detail
