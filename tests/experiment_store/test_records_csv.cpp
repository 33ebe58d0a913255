// The long-format trial CSV (records.hpp): every field round trips through
// trials_csv / parse_trials_csv, RFC 4180 quoting, missing = empty cell,
// columns in any order, and bad cells name their record and column.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <limits>

#include "../support/expect.hpp"

#include "fixtures.hpp"
#include "texel/error.hpp"
#include "texel/experiment/records.hpp"

namespace ex = texel::experiment;
using texel::test_support::full_trial;

namespace {

std::string cell(const std::string& csv_text, const std::string& column, std::size_t record = 1) {
  // Only for rows without quoted line breaks.
  std::vector<std::string> lines;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= csv_text.size(); ++i)
    if (i == csv_text.size() || csv_text[i] == '\n') {
      lines.push_back(csv_text.substr(start, i - start));
      start = i + 1;
    }
  const auto split = [](const std::string& l) {
    std::vector<std::string> out(1);
    for (char c : l) {
      if (c == ',')
        out.emplace_back();
      else
        out.back() += c;
    }
    return out;
  };
  const auto header = split(lines[0]);
  const auto row = split(lines[record]);
  for (std::size_t c = 0; c < header.size(); ++c)
    if (header[c] == column) return row.at(c);
  return "<no column>";
}

}  // namespace

TEST(TrialCsv, HeaderIsTheColumnList) {
  const auto& cols = ex::trial_columns();
  ASSERT_EQ(cols.size(), 60u);  // with the 2-D display's stroke columns, the finger behind the swipe columns, the n-back's
  EXPECT_EQ(cols.front(), "participant");
  EXPECT_EQ(cols[48], "answered_at");
  EXPECT_EQ(cols[53], "suspended_ms");  // trial_number and the timing flags (issue #22)
  // The finger behind the swipe columns come last (issue #36).
  EXPECT_EQ(cols[54], "presentation_mode");
  EXPECT_EQ(cols[55], "finger_source");
  EXPECT_EQ(cols[56], "swipe_flag");
  // The executive distractor's scores come last (issue #40).
  EXPECT_EQ(cols[57], "nback_targets");
  EXPECT_EQ(cols.back(), "nback_false_alarms");
  const auto csv = ex::trials_csv({});
  std::string header;
  for (const auto& c : cols) header += (header.empty() ? "" : ",") + c;
  EXPECT_EQ(csv, header + "\n");
}

TEST(TrialCsv, EveryFieldRoundTrips) {
  std::vector<ex::TrialRow> rows;
  for (int i = 0; i < 3; ++i) rows.push_back(full_trial(i).row);
  rows.push_back(ex::TrialRow{});  // everything missing
  rows[1].response = "\"A\", then B";
  rows[2].condition = "tab\there; semicolon";
  rows[2].intensity = -0.0;
  rows[2].rt_ms = 5e-324;
  rows[2].pitch_db = 1.7976931348623157e308;
  rows[2].iteration = 0;
  rows[2].slider_p = std::numeric_limits<double>::infinity();
  rows[2].slider_i = -std::numeric_limits<double>::infinity();
  const auto csv = ex::trials_csv(rows);
  const auto back = ex::parse_trials_csv(csv, "rows.csv");
  ASSERT_EQ(back.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) TEXEL_EXPECT_ROW_EQ(back[i], rows[i]);
  EXPECT_TRUE(std::signbit(back[2].intensity));
  // Writing what was read gives the same bytes.
  EXPECT_EQ(ex::trials_csv(back), csv);
  // Each row's JSON form (the store's) carries the same cells.
  for (const auto& r : rows) TEXEL_EXPECT_ROW_EQ(ex::row_from_json(ex::row_json(r), "row"), r);
}

TEST(TrialCsv, CellFormats) {
  ex::TrialRow r = full_trial(0).row;
  r.block = "narrow";  // no quoting, so cell() can split on commas
  r.reference = "ref";
  r.rating = ex::missing;
  r.iteration = -1;
  r.practice = true;
  r.reversal = false;
  r.next_intensity = 0.1;
  const auto csv = ex::trials_csv({r});
  EXPECT_EQ(cell(csv, "rating"), "");
  EXPECT_EQ(cell(csv, "iteration"), "");
  EXPECT_EQ(cell(csv, "practice"), "1");
  EXPECT_EQ(cell(csv, "reversal"), "0");
  EXPECT_EQ(cell(csv, "next_intensity"), "0.1");  // shortest round-trip form
  EXPECT_EQ(cell(csv, "rt_ms"), "1234.5678");
  EXPECT_EQ(cell(csv, "texel_length_mm"), "0.25");
  EXPECT_EQ(csv, ex::trials_csv({}) + ex::csv_line(r) + "\n");
  r.pitch_db = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(cell(ex::trials_csv({r}), "pitch_db"), "-Inf");
  // RFC 4180: quotes doubled inside a quoted field; the line break stays in it.
  const auto quoted = ex::csv_line(full_trial(0).row);
  EXPECT_NE(quoted.find(R"(,"narrow, ""fine""",)"), std::string::npos) << quoted;
  EXPECT_NE(quoted.find(",\"line\nbreak\","), std::string::npos) << quoted;
}

TEST(TrialCsv, ColumnsInAnyOrderUnknownIgnoredMissingStayMissing) {
  const std::string text =
      "\xEF\xBB\xBF"
      "extra,rt_ms,participant,iteration,correct,practice\r\n"
      "x,812.5,S07,,1,1\r\n"
      "\"y,z\",,\"S\"\"8\",3,,0\r\n";
  const auto rows = ex::parse_trials_csv(text, "r.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].participant, "S07");
  EXPECT_EQ(rows[0].rt_ms, 812.5);
  EXPECT_EQ(rows[0].iteration, -1);
  EXPECT_EQ(rows[0].correct, 1.0);
  EXPECT_TRUE(rows[0].practice);
  EXPECT_TRUE(std::isnan(rows[0].rating));
  EXPECT_EQ(rows[0].session_id, 0);
  EXPECT_EQ(rows[1].participant, "S\"8");
  EXPECT_TRUE(std::isnan(rows[1].rt_ms));
  EXPECT_EQ(rows[1].iteration, 3);
  EXPECT_TRUE(std::isnan(rows[1].correct));
}

TEST(TrialCsv, BadInputNamesLineAndColumn) {
  const auto msg = [](const std::string& text) {
    return texel::test_support::message_of<texel::FormatError>([&] { (void)ex::parse_trials_csv(text, "r.csv"); });
  };
  EXPECT_EQ(msg("participant,rt_ms\nS1,12\nS2,fast\n"), "r.csv: line 3, column rt_ms: 'fast' is not a number");
  EXPECT_EQ(msg("participant,trial\nS1,1.5\n"), "r.csv: line 2, column trial: '1.5' is not a whole number");
  EXPECT_EQ(msg("participant,trial\nS1,99999999999\n"), "r.csv: line 2, column trial: '99999999999' is out of range");
  EXPECT_EQ(msg("participant,practice\nS1,yes\n"), "r.csv: line 2, column practice: 'yes' is not 0 or 1");
  EXPECT_EQ(msg("participant,trial\nS1\n"), "r.csv:2: row has 1 field(s) but the header has 2");
  EXPECT_EQ(msg("participant\n\"S1\n"), "r.csv:2: a quoted field starting on this line is never closed");
  EXPECT_EQ(msg(""), "r.csv: empty; a CSV table needs a header row");
  EXPECT_EQ(msg("a,b\n1,2\n"), "r.csv: the header names none of the trial columns (participant, trial, …)");
}

// Property: any strings (commas, quotes, CR, LF, NUL, UTF-8) and any doubles
// (NaN = missing, ±0, ±Inf, subnormals) survive trials_csv → parse_trials_csv.
RC_GTEST_PROP(TrialCsvProperty, AnyRowRoundTrips,
              (const std::string& text, const std::string& other, double x, double y, int i, bool b)) {
  ex::TrialRow r;
  r.participant = text;
  r.block = other;
  r.response = text + "," + other;
  r.shown_at = "\"" + other + "\r\n";
  r.session_id = static_cast<std::int64_t>(i) * 3000000000LL;
  r.trial = i;
  r.iteration = i < 0 ? -1 : i;
  r.practice = b;
  r.intensity = x;
  r.rt_ms = y;
  r.rating = std::nextafter(x, y);
  const auto back = ex::parse_trials_csv(ex::trials_csv({r, ex::TrialRow{}, r}), "prop.csv");
  RC_ASSERT(back.size() == 3u);
  const auto same = [](double a, double c) {
    return (std::isnan(a) && std::isnan(c)) || (a == c && std::signbit(a) == std::signbit(c));
  };
  for (std::size_t k : {std::size_t{0}, std::size_t{2}}) {
    RC_ASSERT(back[k].participant == r.participant);
    RC_ASSERT(back[k].block == r.block);
    RC_ASSERT(back[k].response == r.response);
    RC_ASSERT(back[k].shown_at == r.shown_at);
    RC_ASSERT(back[k].session_id == r.session_id);
    RC_ASSERT(back[k].trial == r.trial);
    RC_ASSERT(back[k].iteration == r.iteration);
    RC_ASSERT(back[k].practice == r.practice);
    RC_ASSERT(same(back[k].intensity, r.intensity));
    RC_ASSERT(same(back[k].rt_ms, r.rt_ms));
    RC_ASSERT(same(back[k].rating, r.rating));
  }
  RC_ASSERT(back[1].participant.empty());
  RC_ASSERT(std::isnan(back[1].rt_ms));
}
