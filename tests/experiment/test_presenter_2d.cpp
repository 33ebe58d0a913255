// The 2-D display presenter (docs/experiments.md "The 2-D display
// presenter"): strokes summarised per interval (axial mean direction,
// straightness, speed, jumps and taps), and end to end with the reference
// controller as the display (its simulated sensor strokes along a known
// line): the library presenter records the sensor's direction and flags an
// interval asked along another one; `texel experiment run --finger` with a
// scripted participant stores the strokes with the trial, shows the
// participant nothing of the condition, and refuses a display without a
// sensor in one line.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <thread>

#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/controller_process.hpp"
#include "../support/temp_dir.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/strokes.hpp"
#include "texel/io.hpp"
#include "texel/serial_link.hpp"

namespace ex = texel::experiment;
using json = nlohmann::json;
using namespace std::chrono_literals;

namespace {

const std::string protocols = std::string(TEXEL_TEST_SOURCE_DIR) + "/examples/protocols/";

// Feeds a straight stroke along `deg` at `speed` from (x, y) for `seconds`, 1 kHz.
void stroke(ex::StrokeRecorder& r, double& t, double x, double y, double deg, double speed, double seconds, bool lift = true) {
  const double th = deg * std::numbers::pi / 180;
  for (int i = 0; i <= static_cast<int>(seconds * 1000); ++i, t += 1e-3)
    r.add(t, x + std::cos(th) * speed * i * 1e-3, y + std::sin(th) * speed * i * 1e-3, true);
  if (lift) r.add(t, 0, 0, false);
}

// The direction-independence protocol cut to one block with one trial of
// each given condition (no practice, no time limit).
std::string one_block(const std::vector<std::string>& conditions) {
  json p = json::parse(texel::read_file(protocols + "direction-independence.json"));
  p["blocks"].erase(0);
  json& b = p["blocks"][0];
  b["trials_per_condition"] = 1;
  b["time_limit_s"] = 0;
  json kept = json::array();
  for (const auto& c : b["conditions"])
    if (std::find(conditions.begin(), conditions.end(), c["name"].get<std::string>()) != conditions.end()) kept.push_back(c);
  b["conditions"] = kept;
  return p.dump();
}

}  // namespace

TEST(Strokes, AxialMeanDirectionSpeedAndCompliance) {
  ex::StrokeRecorder r;
  double t = 0;
  stroke(r, t, 50, 50, 60, 100, 0.5);   // along 60°
  stroke(r, t, 75, 93, 240, 100, 0.5);  // and back: the same line
  const ex::IntervalStrokes along = r.summary("1", 60);
  EXPECT_EQ(along.strokes, 2);
  EXPECT_NEAR(along.direction_deg, 60, 0.01);
  EXPECT_NEAR(along.straightness, 1, 1e-9);
  EXPECT_NEAR(along.mean_speed_mm_s, 100, 0.5);
  EXPECT_NEAR(along.path_mm, 100, 0.5);
  EXPECT_TRUE(along.compliant);
  const ex::IntervalStrokes across = r.summary("1", 0);  // asked for 0°, stroked at 60°
  EXPECT_NEAR(across.deviation_deg, 60, 0.01);
  EXPECT_FALSE(across.compliant);
  EXPECT_NEAR(r.summary("1", 170).deviation_deg, 70, 0.01);  // lines: 60° vs 170° differ by 70°

  // A circle has no direction; taps are not strokes; a jump starts a new stroke.
  ex::StrokeRecorder circle;
  t = 0;
  for (int i = 0; i <= 2000; ++i, t += 1e-3)
    circle.add(t, 50 + 20 * std::cos(i * 1e-3 * std::numbers::pi), 50 + 20 * std::sin(i * 1e-3 * std::numbers::pi), true);
  const ex::IntervalStrokes c = circle.summary("2", 0);
  EXPECT_LT(c.straightness, 0.1);
  EXPECT_FALSE(c.compliant);
  ex::StrokeRecorder taps;
  t = 0;
  for (int k = 0; k < 5; ++k) stroke(taps, t, 10.0 * k, 0, 0, 100, 0.02);  // 2 mm each
  EXPECT_EQ(taps.summary("3", 0).strokes, 0);
  EXPECT_FALSE(taps.summary("3", 0).compliant);
  ex::StrokeRecorder jump;
  t = 0;
  stroke(jump, t, 0, 0, 0, 100, 0.5, false);
  stroke(jump, t, 0, 100, 0, 100, 0.5);  // the finger "teleports" 100 mm without a lift
  const ex::IntervalStrokes j = jump.summary("1", 0);
  EXPECT_EQ(j.strokes, 2);
  EXPECT_NEAR(j.path_mm, 100, 0.5);
  EXPECT_NEAR(j.direction_deg, 0, 0.01);

  // The row's columns: every interval must comply.
  ex::TrialRow row;
  ex::fill_stroke_columns({along, along, across}, 3, row);
  EXPECT_EQ(row.strokes, 6);
  EXPECT_NEAR(row.stroke_deviation_deg, 60, 0.01);
  EXPECT_EQ(row.direction_compliant, 0.0);
  ex::fill_stroke_columns({along, along, along}, 3, row);
  EXPECT_EQ(row.direction_compliant, 1.0);
}

TEST(Strokes, DirectionWordsNameOnlyTheLine) {
  EXPECT_EQ(ex::direction_words(0), "↔ left–right (horizontal)");
  EXPECT_EQ(ex::direction_words(180), "↔ left–right (horizontal)");
  EXPECT_EQ(ex::direction_words(-90), "↕ up–down (vertical)");
  EXPECT_EQ(ex::direction_words(60), "⤡ falling to the right, 60° from horizontal");  // y points down the screen
  EXPECT_EQ(ex::direction_words(240), "⤡ falling to the right, 60° from horizontal");
  EXPECT_EQ(ex::direction_words(135), "⤢ rising to the right, 45° from horizontal");
}

// The reference controller's sensor in a loop lifts between its strokes,
// as a finger does (docs/serial-protocol.md): the report before every return
// to the stroke's start is a lifted one, so a stroke recorder separates the
// strokes without its jump rule (here switched off: any speed, any gap).
TEST(Presenter2D, TheControllersSensorLiftsBetweenItsStrokes) {
  texel::test_support::ControllerProcess display(
      TEXEL_CLI, {"--sensor", "line", "--sensor-angle", "0", "--sensor-start", "40,60", "--sensor-period", "0.3", "--sensor-lift",
                  "0.05", "--duration", "30", "--quiet"});
  ASSERT_FALSE(display.pty().empty());
  texel::SerialLink link(display.pty());
  link.hello();
  link.start_reports(1000);
  std::vector<texel::FingerReport> got;
  std::array<texel::FingerReport, 64> buf;
  const auto end = std::chrono::steady_clock::now() + 1600ms;
  while (std::chrono::steady_clock::now() < end) {
    const std::size_t n = link.read_reports(buf, 20);
    got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  }
  link.start_reports(0);
  ASSERT_GT(got.size(), 500u);
  ex::StrokeRules rules;
  rules.max_speed_mm_s = 1e9;
  rules.max_gap_s = 1e9;
  ex::StrokeRecorder recorder(rules);
  int lifts = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const texel::FingerReport& r = got[i];
    recorder.add(r.t_us * 1e-6, r.x_mm, r.y_mm, r.touch);
    if (i == 0) continue;
    const texel::FingerReport& prev = got[i - 1];
    lifts += prev.touch && !r.touch;
    // Touching, the finger moves 100 mm/s: never a jump between two reports.
    if (prev.touch && r.touch && r.t_us - prev.t_us < 10000) {
      EXPECT_LT(std::abs(r.x_mm - prev.x_mm), 2.0) << "report " << i << ": a jump while touching";
    }
  }
  // 1.6 s of 0.35 s passes: four or five lifts, one stroke each side of them.
  EXPECT_GE(lifts, 4);
  EXPECT_LE(lifts, 5);
  const ex::IntervalStrokes summary = recorder.summary("1", 0.0);
  EXPECT_GE(summary.strokes, lifts);
  EXPECT_LE(summary.strokes, lifts + 1);
  EXPECT_NEAR(summary.direction_deg, 0.0, 0.5);
}

// The library presenter with the reference controller as the display: its
// sensor strokes along 60° from (60, 40) at 100 mm/s, lifting every 0.6 s.
TEST(Presenter2D, RecordsTheDisplaysStrokesPerInterval) {
  texel::test_support::ControllerProcess display(TEXEL_CLI, {"--sensor", "line", "--sensor-angle", "60", "--sensor-start",
                                                             "60,40", "--sensor-period", "0.6", "--duration", "30", "--quiet"});
  ASSERT_FALSE(display.pty().empty());
  ex::PresenterOptions o;
  o.backend = "serial:" + display.pty();  // one link: finger reports in, drive values out
  o.finger = ex::FingerSource::display;
  o.finger_display = o.backend;
  ex::Presenter presenter(o);
  ASSERT_TRUE(presenter.two_d());
  EXPECT_THROW(presenter.show("{}"), texel::InvalidArgument);  // a 2-D display plays stimuli, not 1-D documents

  const ex::Protocol protocol = ex::parse_protocol(one_block({"path-indexed 0/60", "oriented 0/60"}));
  ex::Session session(protocol, ex::SessionContext{});
  // The preload renders the session's two friction bitmaps (the oriented
  // condition's pair and odd fields) in the background; no trial renders one.
  presenter.preload(protocol, session.context());
  for (int k = 0; k < 6000 && !presenter.preloaded(); ++k) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(presenter.preloaded());
  EXPECT_EQ(presenter.bitmap_counts().preloaded, 2);
  for (int trial = 0; trial < 2; ++trial) {
    const ex::Question& q = session.question();
    ASSERT_EQ(q.surfaces.size(), 3u);
    presenter.prepare(q);
    for (std::size_t i = 0; i < 3; ++i) {
      presenter.show(q, i);
      for (int k = 0; k < 70; ++k) {  // 0.7 s: at least one whole stroke
        presenter.pump();
        std::this_thread::sleep_for(10ms);
      }
    }
    presenter.blank();
    ASSERT_EQ(presenter.error(), "");
    EXPECT_EQ(presenter.bitmap_counts().at_trial, 0);
    ex::Response r;
    r.choice = "1";
    r.strokes = presenter.strokes(q);
    ASSERT_EQ(r.strokes.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      const ex::IntervalStrokes& s = r.strokes[i];
      SCOPED_TRACE("trial " + std::to_string(trial) + ", interval " + s.stimulus);
      EXPECT_GE(s.strokes, 1);
      EXPECT_NEAR(s.direction_deg, 60, 0.5);
      EXPECT_NEAR(s.mean_speed_mm_s, 100, 5);
      EXPECT_EQ(s.instructed_deg, q.surfaces[i].direction_deg);
      EXPECT_EQ(s.compliant, q.surfaces[i].direction_deg == 60) << "asked along " << q.surfaces[i].direction_deg;
    }
    // Stored with the trial and read back exactly (resume replays it).
    const ex::StoredTrial t = session.answer(r);
    EXPECT_EQ(ex::Response::from_json(t.response_json).to_json(), t.response_json);
    EXPECT_EQ(t.row.direction_compliant, 0.0);  // a 0/60 pair always has an interval asked along 0°
    EXPECT_NEAR(t.row.stroke_deviation_deg, 60, 0.5);
    EXPECT_NEAR(t.row.swipe_mean_speed_mm_s, 100, 5);
  }
  const auto counts = presenter.finger_counts();
  presenter.stop();
  EXPECT_GT(counts.reports, 1000u);
  EXPECT_EQ(counts.lost, 0u);
  EXPECT_NE(display.stop().find("bad 0, nacks 0"), std::string::npos);
}

// `texel experiment run --finger` with a participant typing at the terminal
// (a script with pauses) and stroking the controller's sensor along 0°.
TEST(Presenter2D, TerminalRunStoresStrokesAndShowsNothingOfTheCondition) {
  texel::test_support::TempDir tmp("presenter-2d");
  texel::write_file_atomic(tmp.at("p.json"), one_block({"path-indexed 0/60"}));
  texel::test_support::ControllerProcess display(TEXEL_CLI, {"--sensor", "line", "--sensor-angle", "0", "--sensor-start", "40,60",
                                                             "--sensor-period", "0.6", "--duration", "30", "--quiet"});
  ASSERT_FALSE(display.pty().empty());
  const std::string port = "serial:" + display.pty();
  // The participant feels each interval for 0.9 s from the moment it plays
  // (the monitor's `play` line), however long the run took to start.
  const std::string m = tmp.at("m.txt");
  auto felt = [&](int stimulus) {
    return "until grep -q 'play .*stimulus=" + std::to_string(stimulus) + "' " + m +
           " 2>/dev/null; do sleep 0.05; done; sleep 0.9; ";
  };
  const std::string cmd = "(" + felt(1) + "echo 2; " + felt(2) + "echo 3; " + felt(3) + "echo 'a 2') | " +
                          std::string(TEXEL_CLI) + " experiment run " + tmp.at("p.json") + " --participant P01 --db " +
                          tmp.at("s.db") + " --backend null --finger " + port + " --monitor " + tmp.at("m.txt") + " 2>&1";
  std::string screen;
  FILE* p = ::popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) screen += buf;
  ASSERT_EQ(WEXITSTATUS(::pclose(p)), 0) << screen;
  EXPECT_NE(screen.find("Stroke along: "), std::string::npos) << screen;
  for (const char* leak : {"path-indexed", "spectral", "oriented", "0/60", "condition", "correct", "deviation", "compliant",
                           "strokes=", "direction_deg", "mode"})
    EXPECT_EQ(screen.find(leak), std::string::npos) << leak << " on the participant's screen:\n" << screen;

  const auto csv = texel::test_support::run_cli(TEXEL_CLI, "experiment export --db " + tmp.at("s.db") + " -o " + tmp.at("t.csv"));
  ASSERT_EQ(csv.status, 0) << csv.out;
  const std::string monitor = texel::read_file(tmp.at("m.txt"));
  // Each interval's strokes reach the monitor; those asked along 60° are flagged.
  int flagged = 0, along = 0;
  for (std::size_t at = monitor.find(" strokes "); at != std::string::npos; at = monitor.find(" strokes ", at + 1)) {
    const std::string line = monitor.substr(at, monitor.find('\n', at) - at);
    EXPECT_NE(line.find("direction_deg=0.0"), std::string::npos) << line;
    const bool asked_60 = line.find("instructed_deg=60.0") != std::string::npos;
    EXPECT_NE(line.find(asked_60 ? "compliant=0" : "compliant=1"), std::string::npos) << line;
    ++(asked_60 ? flagged : along);
  }
  EXPECT_EQ(flagged + along, 3) << monitor;
  EXPECT_GE(flagged, 1) << monitor;
  const std::string table = texel::read_file(tmp.at("t.csv"));
  EXPECT_NE(table.find("stroke_deviation_deg"), std::string::npos);

  const auto an = texel::test_support::run_cli(TEXEL_CLI, "experiment analyze --db " + tmp.at("s.db") + " --json", false);
  ASSERT_EQ(an.status, 0) << an.out;
  const json s = json::parse(an.out);
  const json& d = s.contains("summary") ? s["summary"]["direction-independence"] : s["direction-independence"];
  const json& compliance = d["conditions"][0]["direction_compliance"];
  EXPECT_EQ(compliance["trials_stroked"], 1);
  EXPECT_EQ(compliance["compliant"], 0);
  EXPECT_NEAR(compliance["deviation_deg_median"].get<double>(), 60, 0.5);

  // A display without a sensor, a 1-D protocol in another mode than host-streams, a simulated participant:
  // one line each, nothing written.
  texel::test_support::ControllerProcess blind(TEXEL_CLI, {"--duration", "30", "--quiet"});
  for (const auto& [args, words] : std::vector<std::pair<std::string, std::string>>{
           {tmp.at("p.json") + " --finger serial:" + blind.pty(), "no finger sensor"},
           {protocols + "texel-length.json --finger " + port + " --mode display-plays", "give --mode host-streams"},
           {tmp.at("p.json") + " --finger " + port + " --simulate default", "does not stroke"}}) {
    const auto no = texel::test_support::run_cli(
        TEXEL_CLI, "experiment run " + args + " --participant P02 --db " + tmp.at("n.db") + " --backend null");
    EXPECT_EQ(no.status, 2) << no.out;
    EXPECT_NE(no.out.find(words), std::string::npos) << no.out;
    EXPECT_EQ(std::count(no.out.begin(), no.out.end(), '\n'), 1) << no.out;
    EXPECT_FALSE(std::filesystem::exists(tmp.at("n.db")));
  }
}
