// libFuzzer target for the CSV readers of outside input; the first byte
// picks the parser, the rest is its text:
//   even: two-column numeric CSV (parse_csv_columns, io.hpp: position or time
//         against amplitude); what parses has two equal, non-empty columns
//         and reads back the same from csv_columns;
//   odd:  finger traces (parse_trace_csv, finger.hpp: time_s,position_mm
//         [,touch]); what parses is finite, in time order, and reads back
//         the same from trace_csv.
// Every input is accepted or rejected with texel::FormatError; anything else
// (a crash, another exception, a sanitizer report) is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "texel/error.hpp"
#include "texel/finger.hpp"
#include "texel/io.hpp"

namespace {

bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

void columns(std::string_view text) {
  const auto parsed = texel::parse_csv_columns(text, "fuzz");
  const auto& a = parsed.first;
  const auto& b = parsed.second;
  if (a.empty() || a.size() != b.size()) std::abort();
  const auto again = texel::parse_csv_columns(texel::csv_columns("x", "y", a, b), "again");
  if (again.first.size() != a.size() || again.second.size() != b.size()) std::abort();
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same(again.first[i], a[i]) || !same(again.second[i], b[i])) std::abort();
}

void trace(std::string_view text) {
  const auto t = texel::parse_trace_csv(text, "fuzz");
  if (t.empty()) std::abort();
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i].t_s) || !std::isfinite(t[i].x_mm)) std::abort();
    if (i > 0 && t[i].t_s < t[i - 1].t_s) std::abort();
  }
  const auto again = texel::parse_trace_csv(texel::trace_csv(t), "again");
  if (again.size() != t.size()) std::abort();
  for (std::size_t i = 0; i < t.size(); ++i)
    if (again[i].t_s != t[i].t_s || again[i].x_mm != t[i].x_mm || again[i].touch != t[i].touch) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    if (data[0] % 2 == 0)
      columns(text);
    else
      trace(text);
  } catch (const texel::FormatError&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
