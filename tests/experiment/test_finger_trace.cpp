// The finger that explored a trial (finger_trace.hpp): the swipe measures
// come from the samples' own time stamps whatever their arrival, implausible
// traces are flagged and never become data, the stored text round-trips, the
// presentation modes parse, and a Session stores the trace and fills the
// row's swipe columns from it (a display's or pointer's trace wins; a
// simulated finger only fills what nothing else did).
#include <gtest/gtest.h>

#include <cmath>

#include "texel/error.hpp"
#include "texel/experiment/finger_trace.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/session.hpp"
#include "texel/io.hpp"

namespace ex = texel::experiment;

namespace {

// Strokes to the right at `speed` (mm/s) for `stroke_s`, lifted for 0.1 s
// between them, sampled every `dt` seconds.
std::vector<texel::FingerSample> strokes(double speed, double stroke_s, int count, double dt) {
  std::vector<texel::FingerSample> out;
  double t = 0;
  for (int k = 0; k < count; ++k) {
    for (int i = 0; i * dt <= stroke_s + 1e-12; ++i, t += dt) out.push_back({t, 10 + speed * i * dt, true});
    out.push_back({t, 10 + speed * stroke_s, false});
    t += 0.1;
  }
  return out;
}

const std::string protocols = std::string(TEXEL_TEST_SOURCE_DIR) + "/examples/protocols/";

}  // namespace

TEST(FingerTrace, MeasuresComeFromTheSamplesOwnTimes) {
  ex::FingerTrace t;
  t.source = ex::TraceSource::display;
  t.samples = strokes(80.0, 0.5, 4, 0.001);
  const ex::TraceMeasures m = measure_trace(t);
  ASSERT_TRUE(m.measures) << m.flag;
  EXPECT_EQ(m.flag, "");
  EXPECT_NEAR(m.measures->mean_speed_mm_s, 80.0, 1e-6);
  EXPECT_NEAR(m.measures->sd_speed_mm_s, 0.0, 1e-3);  // t += dt rounding
  EXPECT_NEAR(m.measures->directional_proportion, 1.0, 1e-12);
  // Unevenly spaced samples (a pointer's events, a display that skipped
  // reports) at the same finger speed give the same speed.
  ex::FingerTrace uneven = t;
  uneven.samples.clear();
  double time = 0;
  for (int i = 0; i < 300; ++i) {
    uneven.samples.push_back({time, 80.0 * time, true});
    time += (i % 3 == 0) ? 0.017 : 0.004;
  }
  EXPECT_NEAR(measure_trace(uneven).measures->mean_speed_mm_s, 80.0, 1e-6);
  // Back and forth: the proportion of intervals moving right minus left.
  ex::FingerTrace back = t;
  back.samples.clear();
  for (int i = 0; i <= 1000; ++i) back.samples.push_back({i * 1e-3, i <= 750 ? i * 0.1 : 150 - i * 0.1, true});
  EXPECT_NEAR(measure_trace(back).measures->directional_proportion, (750.0 - 250.0) / 1000.0, 1e-9);
}

TEST(FingerTrace, ImplausibleTracesAreFlaggedNotMeasured) {
  ex::FingerTrace t;
  t.source = ex::TraceSource::pointer;
  // Thirty samples 1 mm apart, all stamped at one instant (a burst stamped on arrival).
  for (int i = 0; i < 30; ++i) t.samples.push_back({1.0, static_cast<double>(i), true});
  ex::TraceMeasures m = measure_trace(t);
  EXPECT_FALSE(m.measures);
  EXPECT_EQ(ex::flag_code(m.flag), "implausible_speed") << m.flag;
  // A jump between two touching samples (a missed lift): 50 mm in 1 ms.
  t.samples = strokes(100.0, 0.3, 1, 0.001);
  t.samples.insert(t.samples.begin() + 100, {t.samples[99].t_s + 0.0005, t.samples[99].x_mm + 50, true});
  m = measure_trace(t);
  EXPECT_EQ(ex::flag_code(m.flag), "implausible_speed") << m.flag;
  EXPECT_GT(m.max_speed_mm_s, ex::max_plausible_speed_mm_s);
  // Time running backwards.
  t.samples = {{0.0, 1, true}, {0.002, 1.2, true}, {0.001, 1.3, true}};
  EXPECT_EQ(measure_trace(t).flag, "time_not_increasing: sample 3 at 0.001000 s follows one at 0.002000 s");
  // Never touched.
  t.samples = {{0.0, 1, false}, {0.1, 5, false}};
  EXPECT_EQ(measure_trace(t).flag, "no_touch");
}

TEST(FingerTrace, OneRuleForEverySourceShortTracesAndCoarseClocks) {
  // Too little of a swipe to measure: 3 intervals over 3 ms.
  std::vector<texel::FingerSample> s = {{0.0, 1, true}, {0.001, 1.1, true}, {0.002, 1.2, true}, {0.003, 1.3, true}};
  ex::TraceMeasures m = ex::measure_trace(s);
  EXPECT_FALSE(m.measures);
  EXPECT_EQ(m.flag, "too_short: 3 intervals over 0.003 s touched; needed: at least 5 intervals and 0.1 s");
  // A browser rounding PointerEvent.timeStamp to 1 ms at a 4 kHz pointer: pairs of samples share a
  // stamp (0.025 mm apart, an infinite speed between them) yet the hand moves at 100 mm/s.
  s.clear();
  for (int i = 0; i < 2000; ++i) s.push_back({std::floor(i * 0.25) * 1e-3, 10 + i * 0.025, true});
  m = ex::measure_trace(s);
  ASSERT_TRUE(m.measures) << m.flag;
  EXPECT_GT(m.max_speed_mm_s, 50.0);  // a lower bound: 2 ms of stamps timed as 3 ms
  EXPECT_LE(m.max_speed_mm_s, 100.0);
  EXPECT_EQ(ex::flag_code("implausible_speed: mean 1 mm/s"), "implausible_speed");
  EXPECT_EQ(ex::flag_code("no_touch"), "no_touch");
  // The limits are checked.
  EXPECT_THROW(ex::measure_trace(s, {.max_speed_mm_s = 0}), texel::InvalidArgument);
  // Stricter limits flag what the defaults take.
  EXPECT_EQ(ex::flag_code(ex::measure_trace(s, {.max_speed_mm_s = 50}).flag), "implausible_speed");
}

TEST(FingerTrace, StoredTextRoundTripsAndBadLinesNameThemselves) {
  const std::vector<texel::FingerSample> s = {{0.0, 10.0, true}, {4294.967296, -0.000001, false}, {12.5, 101.76, true}};
  const std::string text = ex::trace_samples_text(s);
  EXPECT_EQ(text, "0.000000,10.000000,1\n4294.967296,-0.000001,0\n12.500000,101.760000,1\n");
  const auto back = ex::parse_trace_samples(text, "t");
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(back[i].t_s, s[i].t_s);
    EXPECT_DOUBLE_EQ(back[i].x_mm, s[i].x_mm);
    EXPECT_EQ(back[i].touch, s[i].touch);
  }
  try {
    (void)ex::parse_trace_samples("0,1,1\n0.1,2,7\n", "db: session 1 trial 0");
    FAIL();
  } catch (const texel::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("db: session 1 trial 0: finger trace line 2"), std::string::npos) << e.what();
  }
}

TEST(FingerTrace, ModesAndSourcesParseAndRefuseNaming) {
  for (const auto m : {ex::PresentationMode::display_plays, ex::PresentationMode::host_streams, ex::PresentationMode::passive})
    EXPECT_EQ(ex::parse_presentation_mode(to_string(m)), m);
  EXPECT_EQ(to_string(ex::PresentationMode::display_plays), "display-plays");
  try {
    (void)ex::parse_presentation_mode("display", "--mode");
    FAIL();
  } catch (const texel::InvalidArgument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--mode"), std::string::npos) << m;
    EXPECT_NE(m.find("display-plays, host-streams, passive"), std::string::npos) << m;
  }
  EXPECT_EQ(ex::parse_trace_source("simulated"), ex::TraceSource::simulated);
  EXPECT_THROW((void)ex::parse_trace_source("mouse"), texel::InvalidArgument);
}

// The Session stores the trace and computes the row's swipe columns from it.
TEST(FingerTrace, SessionFillsTheSwipeColumnsFromTheTrace) {
  const ex::Protocol p = ex::load_protocol(protocols + "texel-length.json");
  ex::Session s(p, ex::SessionContext{"P1", 1, 7, {}});
  const auto answer = [&](ex::Response r) {
    r.choice = s.question().choices.empty() ? "" : s.question().choices.front();
    return s.answer(r);
  };
  // A display's trace replaces what the response carried.
  ex::Response r;
  r.swipe_mean_speed_mm_s = 500.0;
  r.trace.source = ex::TraceSource::display;
  r.trace.mode = ex::PresentationMode::display_plays;
  r.trace.samples = strokes(60.0, 0.5, 3, 0.001);
  ex::StoredTrial t = answer(r);
  EXPECT_NEAR(t.row.swipe_mean_speed_mm_s, 60.0, 1e-6);
  EXPECT_NEAR(t.row.directional_proportion, 1.0, 1e-12);
  EXPECT_EQ(t.row.presentation_mode, "display-plays");
  EXPECT_EQ(t.row.finger_source, "display");
  EXPECT_EQ(t.row.swipe_flag, "");
  EXPECT_EQ(t.trace.samples.size(), r.trace.samples.size());
  // A simulated finger keeps a simulated observer's drawn values...
  ex::Response sim;
  sim.swipe_mean_speed_mm_s = 123.0;
  sim.swipe_sd_speed_mm_s = 4.0;
  sim.directional_proportion = 0.1;
  sim.trace.source = ex::TraceSource::simulated;
  sim.trace.mode = ex::PresentationMode::passive;
  sim.trace.samples = strokes(100.0, 0.5, 2, 0.001);
  t = answer(sim);
  EXPECT_EQ(t.row.swipe_mean_speed_mm_s, 123.0);
  EXPECT_EQ(t.row.finger_source, "simulated");
  EXPECT_EQ(t.row.presentation_mode, "passive");
  // ...and fills them when nothing else did.
  sim.swipe_mean_speed_mm_s.reset();
  sim.swipe_sd_speed_mm_s.reset();
  sim.directional_proportion.reset();
  t = answer(sim);
  EXPECT_NEAR(t.row.swipe_mean_speed_mm_s, 100.0, 1e-6);
  // A flagged trace leaves the columns empty, even over the response's values.
  ex::Response bad;
  bad.swipe_mean_speed_mm_s = 80.0;
  bad.trace.source = ex::TraceSource::pointer;
  for (int i = 0; i < 30; ++i) bad.trace.samples.push_back({0.5, static_cast<double>(i), true});
  t = answer(bad);
  EXPECT_TRUE(std::isnan(t.row.swipe_mean_speed_mm_s));
  EXPECT_TRUE(std::isnan(t.row.swipe_sd_speed_mm_s));
  EXPECT_EQ(ex::flag_code(t.row.swipe_flag), "implausible_speed") << t.row.swipe_flag;
}
