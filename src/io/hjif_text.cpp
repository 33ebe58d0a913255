// Text-level helpers of the .hjif reader and checker (hjif_internal.hpp):
// the nesting depth of a text before it is parsed, the schema's RFC 3339
// date-time and the reference software's more liberal dates, values quoted
// for one-line messages, and exact powers of ten.
#include <algorithm>
#include <cstdlib>
#include <string>
#include <string_view>

#include "hjif_internal.hpp"

namespace texel::hjif::detail {

std::size_t nesting_depth(std::string_view t, std::size_t limit) {
  std::size_t depth = 0;
  std::size_t most = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const char c = t[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"')
      in_string = true;
    else if (c == '[' || c == '{') {
      most = std::max(most, ++depth);
      if (most > limit) return most;
    } else if ((c == ']' || c == '}') && depth > 0)
      --depth;
  }
  return most;
}

namespace {

bool digits(std::string_view s, std::size_t at, std::size_t n) {
  if (at + n > s.size()) return false;
  for (std::size_t i = at; i < at + n; ++i)
    if (s[i] < '0' || s[i] > '9') return false;
  return true;
}
int value(std::string_view s, std::size_t at, std::size_t n) {
  int v = 0;
  for (std::size_t i = at; i < at + n; ++i) v = v * 10 + (s[i] - '0');
  return v;
}
/// YYYY-MM-DD with a real day of the month.
bool calendar_date(std::string_view s) {
  if (s.size() < 10 || !digits(s, 0, 4) || s[4] != '-' || !digits(s, 5, 2) || s[7] != '-' || !digits(s, 8, 2)) return false;
  const int y = value(s, 0, 4), m = value(s, 5, 2), d = value(s, 8, 2);
  static constexpr int days[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (m < 1 || m > 12 || d < 1) return false;
  const bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  return d <= days[m - 1] + (m == 2 && leap ? 1 : 0);
}
/// HH:MM[:SS[.frac]] from `at`; returns the index after it, or npos.
std::size_t clock_time(std::string_view s, std::size_t at, bool seconds_required) {
  if (!digits(s, at, 2) || at + 2 >= s.size() || s[at + 2] != ':' || !digits(s, at + 3, 2)) return std::string_view::npos;
  if (value(s, at, 2) > 23 || value(s, at + 3, 2) > 59) return std::string_view::npos;
  std::size_t i = at + 5;
  if (i < s.size() && s[i] == ':') {
    if (!digits(s, i + 1, 2) || value(s, i + 1, 2) > 59) return std::string_view::npos;
    i += 3;
    if (i < s.size() && s[i] == '.') {
      const std::size_t start = ++i;
      while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
      if (i == start) return std::string_view::npos;
    }
  } else if (seconds_required) {
    return std::string_view::npos;
  }
  return i;
}
/// Z or ±HH:MM from `at`; returns the index after it, or npos.
std::size_t zone(std::string_view s, std::size_t at) {
  if (at < s.size() && (s[at] == 'Z' || s[at] == 'z')) return at + 1;
  if (at < s.size() && (s[at] == '+' || s[at] == '-') && digits(s, at + 1, 2) && at + 3 < s.size() && s[at + 3] == ':' &&
      digits(s, at + 4, 2) && value(s, at + 1, 2) <= 23 && value(s, at + 4, 2) <= 59)
    return at + 6;
  return std::string_view::npos;
}

}  // namespace

std::string quote_value(std::string_view v) {
  std::string out = "'";
  for (std::size_t i = 0; i < v.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(v[i]);
    if (c < 0x20 || c == 0x7F) {
      static constexpr char hex[] = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + (v.size() > 40 ? "…'" : "'");
}

bool rfc3339_date_time(std::string_view s) {
  if (s.size() > 64 || !calendar_date(s) || s.size() < 11 || (s[10] != 'T' && s[10] != 't')) return false;
  const std::size_t t = clock_time(s, 11, true);
  if (t == std::string_view::npos) return false;
  const std::size_t z = zone(s, t);
  return z == s.size();
}

bool liberal_date(std::string_view s) {
  if (s.size() > 64 || !calendar_date(s)) return false;
  if (s.size() == 10) return true;
  if (s[10] != 'T' && s[10] != 't' && s[10] != ' ') return false;
  const std::size_t t = clock_time(s, 11, false);
  if (t == std::string_view::npos) return false;
  if (t == s.size()) return true;
  std::size_t z = t;
  if (s[z] == ' ') ++z;  // "2026-11-26 14:06:29 +01:00"
  return zone(s, z) == s.size();
}

double pow10i(int k) {
  double p = 1.0;
  for (int i = 0; i < std::abs(k); ++i) p *= 10.0;
  return k < 0 ? 1.0 / p : p;
}

}  // namespace texel::hjif::detail
