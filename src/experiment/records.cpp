// The long-format trial rows as CSV (records.hpp). One table of fields
// drives the header, the writer and the reader, so they cannot disagree.
#include "texel/experiment/records.hpp"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <limits>
#include <map>

#include <nlohmann/json.hpp>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/table.hpp"

namespace texel::experiment {
namespace {

struct Field {
  const char* name;
  std::function<std::string(const TrialRow&)> get;
  std::function<void(TrialRow&, const std::string&)> set;  // throws std::invalid_argument on a bad value
};

double parse_number(const std::string& s) {
  if (s.empty() || s == "NA" || s == "nan" || s == "NaN") return missing;
  double d = 0;
  const auto res = std::from_chars(s.data(), s.data() + s.size(), d);
  if (res.ec != std::errc() || res.ptr != s.data() + s.size()) throw std::invalid_argument("not a number");
  return d;
}
// Shortest round-trip form; NaN (missing) is an empty cell, infinities are
// written the way R, pandas and MATLAB read them.
std::string show_number(double d) {
  if (std::isnan(d)) return {};
  if (std::isinf(d)) return d > 0 ? "Inf" : "-Inf";
  return texel::detail::num(d);
}

// A whole number of type T; "3.0" is accepted (spreadsheets write it), "3.5"
// and values outside T are not.
template <class T>
T parse_whole(const std::string& s) {
  // Plain integers exactly (session ids may exceed 2^53); other spellings
  // of a whole number ("3.0", "1e3", from spreadsheets) through double.
  T exact{};
  const auto res = std::from_chars(s.data(), s.data() + s.size(), exact);
  if (res.ec == std::errc() && res.ptr == s.data() + s.size()) return exact;
  if (res.ec == std::errc::result_out_of_range) throw std::invalid_argument("out of range");
  const double d = parse_number(s);
  if (!std::isfinite(d) || d != std::floor(d)) throw std::invalid_argument("not a whole number");
  // Exactly representable bounds: -2^63 / -2^31 and 2^63 / 2^31.
  const double lo = static_cast<double>(std::numeric_limits<T>::min());
  const double hi = -lo;
  if (d < lo || d >= hi) throw std::invalid_argument("out of range");
  return static_cast<T>(d);
}

#define TEXEL_STRING(f)                                                                            \
  Field {                                                                                          \
#f, [](const TrialRow& r) { return r.f; }, [](TrialRow & r, const std::string& v) { r.f = v; } \
  }
#define TEXEL_NUMBER(f)                                                                                                       \
  Field {                                                                                                                     \
#f, [](const TrialRow& r) { return show_number(r.f); }, [](TrialRow & r, const std::string& v) { r.f = parse_number(v); } \
  }
#define TEXEL_INT(f)                                                                                                             \
  Field {                                                                                                                        \
#f, [](const TrialRow& r) { return std::to_string(r.f); }, [](TrialRow & r,                                                  \
                                                                  const std::string& v) { r.f = parse_whole<decltype(r.f)>(v); } \
  }
#define TEXEL_BOOL(f)                                                                                         \
  Field {                                                                                                     \
#f, [](const TrialRow& r) { return std::string(r.f ? "1" : "0"); }, [](TrialRow& r, const std::string& v) { \
          if (v == "1" || v == "TRUE" || v == "true") r.f = true;                         \
          else if (v == "0" || v == "FALSE" || v == "false" || v.empty()) r.f = false;    \
          else throw std::invalid_argument("not 0 or 1");                                 \
        } \
  }

const std::vector<Field>& fields() {
  static const std::vector<Field> f = {
      TEXEL_STRING(participant),
      TEXEL_INT(session_id),
      TEXEL_STRING(protocol),
      TEXEL_STRING(study),
      TEXEL_STRING(block),
      TEXEL_INT(block_index),
      TEXEL_INT(trial),
      TEXEL_INT(trial_in_block),
      TEXEL_BOOL(practice),
      TEXEL_STRING(task),
      TEXEL_STRING(condition),
      TEXEL_STRING(reference),
      TEXEL_STRING(variable),
      TEXEL_NUMBER(intensity),
      TEXEL_BOOL(reversal),
      TEXEL_NUMBER(next_intensity),
      TEXEL_BOOL(procedure_finished),
      TEXEL_STRING(response),
      TEXEL_STRING(correct_answer),
      TEXEL_NUMBER(correct),
      TEXEL_NUMBER(rating),
      TEXEL_NUMBER(confidence),
      TEXEL_NUMBER(rt_ms),
      TEXEL_NUMBER(slider_p),
      TEXEL_NUMBER(slider_i),
      TEXEL_NUMBER(pitch_db),
      TEXEL_NUMBER(irregularity_db),
      TEXEL_NUMBER(pitch_a_db),
      TEXEL_NUMBER(irregularity_a_db),
      TEXEL_NUMBER(pitch_b_db),
      TEXEL_NUMBER(irregularity_b_db),
      Field{
          "iteration", [](const TrialRow& r) { return r.iteration >= 0 ? std::to_string(r.iteration) : std::string(); },
          [](TrialRow& r, const std::string& v) { r.iteration = parse_number(v) != parse_number(v) ? -1 : parse_whole<int>(v); }},
      TEXEL_NUMBER(reference_pitch_db),
      TEXEL_NUMBER(reference_irregularity_db),
      TEXEL_NUMBER(texel_length_mm),
      TEXEL_NUMBER(coarse_strength),
      TEXEL_NUMBER(fine_strength),
      TEXEL_NUMBER(quantization_db),
      TEXEL_NUMBER(digit_cell),
      TEXEL_NUMBER(digit_response),
      TEXEL_NUMBER(digit_correct),
      TEXEL_NUMBER(swipe_mean_speed_mm_s),
      TEXEL_NUMBER(swipe_sd_speed_mm_s),
      TEXEL_NUMBER(directional_proportion),
      TEXEL_NUMBER(strokes),
      TEXEL_NUMBER(stroke_deviation_deg),
      TEXEL_NUMBER(direction_compliant),
      TEXEL_STRING(shown_at),
      TEXEL_STRING(answered_at),
      // Derived from `trial`; read back only to check it is a whole number.
      Field{"trial_number", [](const TrialRow& r) { return std::to_string(r.trial + 1); },
            [](TrialRow&, const std::string& v) {
              if (!v.empty()) (void)parse_whole<int>(v);
            }},
      TEXEL_NUMBER(time_limit_s),
      TEXEL_NUMBER(over_time_limit),
      TEXEL_NUMBER(interrupted),
      TEXEL_NUMBER(suspended_ms),
      TEXEL_STRING(presentation_mode),
      TEXEL_STRING(finger_source),
      TEXEL_STRING(swipe_flag),
      TEXEL_NUMBER(nback_targets),
      TEXEL_NUMBER(nback_hits),
      TEXEL_NUMBER(nback_false_alarms),
  };
  return f;
}

std::string quote(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

std::string utc_timestamp() {
  const auto now = std::chrono::system_clock::now();
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count();
  const std::time_t secs = static_cast<std::time_t>(ms / 1000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour,
                tm.tm_min, tm.tm_sec, static_cast<int>(ms % 1000));
  return buf;
}

const std::vector<std::string>& trial_columns() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& f : fields()) n.emplace_back(f.name);
    return n;
  }();
  return names;
}

std::string csv_line(const TrialRow& row) {
  std::string line;
  bool first = true;
  for (const auto& f : fields()) {
    if (!first) line += ',';
    first = false;
    line += quote(f.get(row));
  }
  return line;
}

std::string trials_csv(const std::vector<TrialRow>& rows) {
  std::string out;
  bool first = true;
  for (const auto& n : trial_columns()) {
    out += first ? "" : ",";
    out += n;
    first = false;
  }
  out += '\n';
  for (const auto& r : rows) out += csv_line(r) + '\n';
  return out;
}

std::vector<TrialRow> parse_trials_csv(std::string_view text, std::string_view origin) {
  // One RFC 4180 reader for every CSV the experiments read (table.hpp): it
  // bounds sizes, handles quotes, CRLF and a byte-order mark, and rejects
  // ragged rows naming the line.
  const Table table = parse_csv_table(text, origin);
  std::vector<const Field*> map(table.columns.size(), nullptr);
  std::map<std::string, const Field*, std::less<>> by_name;
  for (const auto& f : fields()) by_name[f.name] = &f;
  bool any = false;
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    if (auto it = by_name.find(table.columns[c]); it != by_name.end()) {
      map[c] = it->second;
      any = true;
    }
  }
  if (!any) throw FormatError(std::string(origin) + ": the header names none of the trial columns (participant, trial, …)");
  std::vector<TrialRow> rows;
  rows.reserve(table.rows());
  for (std::size_t i = 0; i < table.rows(); ++i) {
    const auto& rec = table.cells[i];
    const std::string line = i < table.lines.size() ? std::to_string(table.lines[i]) : std::to_string(i + 2);
    TrialRow r;
    for (std::size_t c = 0; c < rec.size(); ++c) {
      if (!map[c]) continue;
      try {
        map[c]->set(r, rec[c]);
      } catch (const std::invalid_argument& e) {
        throw FormatError(std::string(origin) + ": line " + line + ", column " + map[c]->name + ": '" + rec[c] + "' is " +
                          e.what());
      }
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

std::string row_json(const TrialRow& row) {
  nlohmann::ordered_json j;
  for (const auto& f : fields()) j[f.name] = f.get(row);
  return j.dump();
}

TrialRow row_from_json(std::string_view json_text, std::string_view origin) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(json_text.begin(), json_text.end());
  } catch (const nlohmann::json::exception&) {
    throw FormatError(std::string(origin) + ": malformed row");
  }
  if (!j.is_object()) throw FormatError(std::string(origin) + ": a row must be a JSON object");
  TrialRow r;
  for (const auto& f : fields()) {
    const auto it = j.find(f.name);
    if (it == j.end()) continue;
    if (!it->is_string()) throw FormatError(std::string(origin) + ": column " + f.name + " must be text");
    try {
      f.set(r, it->get<std::string>());
    } catch (const std::invalid_argument& e) {
      throw FormatError(std::string(origin) + ": column " + f.name + " is " + e.what());
    }
  }
  return r;
}

}  // namespace texel::experiment
