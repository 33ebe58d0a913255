// The display in the loop (docs/experiments.md "Running a study with a
// display"): a study against the reference controller as a 1-D display whose
// sensor strokes a scripted finger (strokes at two speeds, a pause, lifts).
//   - In process (the controller on a thread, its every output update
//     logged): the presenter uploads each stimulus as texel render's exact
//     samples, SELECTs it per interval, and the display's output at each
//     sensed x is the selected map's sample there (thousands of updates), 0
//     while lifted and after the blank; the trace the presenter records
//     gives the swipe measures of the stroke script over the same time.
//   - Through `texel experiment run` (texel-length and quantization, cut
//     short; the simulated observer answers while the display's finger
//     explores): the export's swipe columns equal the script's measures
//     within 2 %, every row says display-plays / display, and the display
//     is at rest (STATUS) after the end, 'q', Ctrl-C, SIGTERM and an error.
#include <gtest/gtest.h>
#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <thread>

#include <sqlite3.h>
#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/controller_process.hpp"
#include "../support/temp_dir.hpp"
#include "texel/controller/controller.hpp"
#include "texel/controller/host_hal.hpp"
#include "texel/document.hpp"
#include "texel/experiment/finger_trace.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/store.hpp"
#include "texel/io.hpp"
#include "texel/serial_link.hpp"
#include "texel/stroke_script.hpp"
#include "texel/surface.hpp"

namespace ex = texel::experiment;
using json = nlohmann::json;
using namespace std::chrono_literals;

namespace {

const std::string protocols = std::string(TEXEL_TEST_SOURCE_DIR) + "/examples/protocols/";

// The stroke script, as the controller's `--sensor FILE` reads it
// (time_s,x_mm,y_mm,touch): right at 80 mm/s, a touching pause, left at
// 150 mm/s; then the loop's lift (0.15 s) and again. Between samples the
// controller interpolates linearly; `touch` is the earlier sample's.
constexpr const char* script_csv =
    "time_s,x_mm,y_mm,touch\n"
    "0,20,0,1\n"
    "0.6,68,0,1\n"
    "0.8,68,0,1\n"
    "1.1,23,0,1\n";
constexpr double script_lift_s = 0.15;

// The script as the controller plays it: the same looping rule at the
// display's clock (µs, wrapping at 2³²).
texel::FingerSample script_at(double t_s) {
  struct P {
    double t, x;
  };
  static const P pts[] = {{0, 20}, {0.6, 68}, {0.8, 68}, {1.1, 23}};
  const double period = 1.1;
  const double phase = std::fmod(std::fmod(t_s, 4294.967296), period + script_lift_s);
  if (phase >= period) return {t_s, 23, false};
  std::size_t k = 0;
  while (k + 2 < std::size(pts) && phase >= pts[k + 1].t) ++k;
  const double f = (phase - pts[k].t) / (pts[k + 1].t - pts[k].t);
  return {t_s, pts[k].x + (pts[k + 1].x - pts[k].x) * f, true};
}

// The script's swipe measures at the instants the display reported (a
// display that skipped reports under load weighs the same intervals), so
// only the positions and times the trace holds are under test.
texel::SwipeMeasures script_measures(const std::vector<texel::FingerSample>& trace) {
  std::vector<texel::FingerSample> s;
  for (const auto& sample : trace) s.push_back(script_at(sample.t_s));
  return texel::swipe_measures(s, ex::SwipeLimits{}.still_speed_mm_s);
}

// The display: the reference controller with the scripted sensor, every
// output update logged with the position it played at.
class ScriptedHal final : public texel::controller::Hal {
 public:
  explicit ScriptedHal(int fd) : io_(fd) {}
  std::uint32_t micros() override { return io_.micros(); }
  int serial_read(std::uint8_t* buf, int max) override { return io_.serial_read(buf, max); }
  bool serial_write(const std::uint8_t* buf, int n) override { return io_.serial_write(buf, n); }
  bool read_position(std::int32_t& x_nm, bool& touch) override {
    const texel::FingerSample s = script_at(static_cast<double>(io_.micros()) * 1e-6);
    x_nm = static_cast<std::int32_t>(std::lround(s.x_mm * 1e6));
    touch = s.touch;
    last_x_ = x_nm;
    last_touch_ = touch;
    return true;
  }
  void write_amplitude(std::uint16_t a) override {
    std::lock_guard<std::mutex> lock(mutex);
    log.push_back({last_x_, last_touch_, expect.load(), a});
  }
  void idle_until(std::uint32_t t_us) override { io_.idle_until(t_us); }

  struct Update {
    std::int32_t x_nm;
    bool touch;
    int expect;  // the stimulus the host has selected (-1 none, -2 changing)
    std::uint16_t amplitude;
  };
  std::mutex mutex;
  std::vector<Update> log;
  std::atomic<int> expect{-2};

 private:
  texel::controller::HostHal io_;
  std::int32_t last_x_ = 0;
  bool last_touch_ = false;
};

// texel-length's practice block, `trials` trials of it.
std::string short_texel_length(int trials) {
  json p = json::parse(texel::read_file(protocols + "texel-length.json"));
  json block = p["blocks"][0];
  block["trials"] = trials;
  p["blocks"] = json::array({block});
  return p.dump();
}

// quantization's rating block with its first two pairs.
std::string short_quantization() {
  json p = json::parse(texel::read_file(protocols + "quantization.json"));
  json block = p["blocks"][0];
  json pairs = json::array({block["pairs"][0], block["pairs"][1]});
  block["pairs"] = pairs;
  p["blocks"] = json::array({block});
  return p.dump();
}

std::vector<std::uint16_t> u16_map(const std::string& document_json) {
  const auto bytes = texel::prepare_surface(texel::parse_document(document_json)).render_native(texel::SampleFormat::u16le);
  std::vector<std::uint16_t> out(bytes.size() / 2);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] =
        static_cast<std::uint16_t>(std::to_integer<unsigned>(bytes[2 * i]) | (std::to_integer<unsigned>(bytes[2 * i + 1]) << 8));
  return out;
}

// The display's state as a host asks it (after the run's process has gone).
texel::DisplayStatus status_of(const std::string& pty) {
  texel::SerialLink link(pty);
  link.hello();
  return link.status();
}

}  // namespace

TEST(DisplayLoop, TheDisplayPlaysEachStimulusFromItsOwnSensor) {
  int master = -1, slave = -1;
  char name[256];
  ASSERT_EQ(::openpty(&master, &slave, name, nullptr, nullptr), 0);
  texel::controller::make_raw(slave);
  ScriptedHal hal(master);
  texel::controller::Info info;
  info.name = "scripted-1d";
  auto ctl = std::make_unique<texel::controller::Controller<>>(hal, info);
  std::atomic<bool> stop{false};
  std::thread loop([&] { ctl->run([&] { return stop.load(); }); });
  struct Join {
    std::atomic<bool>& stop;
    std::thread& loop;
    ~Join() {
      stop = true;
      if (loop.joinable()) loop.join();
    }
  } join{stop, loop};

  ex::PresenterOptions o;
  o.backend = std::string("serial:") + name;
  std::optional<ex::Presenter> presenter(std::in_place, o);
  ASSERT_EQ(presenter->mode(), ex::PresentationMode::display_plays);  // 2 slots and a sensor: its HELLO decides
  EXPECT_NE(presenter->describe().find("display-plays"), std::string::npos) << presenter->describe();

  const ex::Protocol protocol = ex::parse_protocol(short_texel_length(2));
  ex::Session session(protocol, ex::SessionContext{"P1", 1, 11, {}});
  // Two slots hold an oddity trial's two different textures (one is shown
  // twice): nothing to warn about; one slot would not.
  EXPECT_TRUE(presenter->check(session.question()).empty());

  std::vector<std::vector<std::uint16_t>> maps;  // per shown stimulus, in show order
  std::vector<std::string> documents;
  for (int trial = 0; trial < 2; ++trial) {
    const ex::Question q = session.question();
    ASSERT_EQ(q.stimuli.size(), 3u);
    presenter->prepare(q);
    for (std::size_t i = 0; i < 3; ++i) {
      maps.push_back(u16_map(q.stimuli[i].document_json));
      documents.push_back(q.stimuli[i].document_json);
      hal.expect = -2;
      presenter->show(q, i);  // returns once the display acknowledged the SELECT
      hal.expect = static_cast<int>(maps.size() - 1);
      for (int k = 0; k < 45; ++k) {  // 0.45 s
        presenter->pump();
        std::this_thread::sleep_for(10ms);
      }
    }
    hal.expect = -2;
    presenter->blank();
    hal.expect = -1;
    std::this_thread::sleep_for(50ms);
    hal.expect = -2;
    ex::Response r;
    r.choice = "2";
    r.trace = presenter->take_trace();
    ASSERT_EQ(presenter->error(), "");
    EXPECT_EQ(r.trace.source, ex::TraceSource::display);
    // ~1.4 s of reports at 1 kHz; a controller starved of CPU skips some (never bursts).
    ASSERT_GT(r.trace.samples.size(), 300u);
    const ex::StoredTrial t = session.answer(r);
    // The swipe columns are the stroke script's over the same span of the display's clock.
    const texel::SwipeMeasures want = script_measures(r.trace.samples);
    SCOPED_TRACE("trial " + std::to_string(trial));
    EXPECT_NEAR(t.row.swipe_mean_speed_mm_s, want.mean_speed_mm_s, 0.02 * want.mean_speed_mm_s);
    EXPECT_NEAR(t.row.swipe_sd_speed_mm_s, want.sd_speed_mm_s, 0.02 * want.sd_speed_mm_s + 0.5);
    EXPECT_NEAR(t.row.directional_proportion, want.directional_proportion, 0.02);
    EXPECT_EQ(t.row.presentation_mode, "display-plays");
    EXPECT_EQ(t.row.finger_source, "display");
    EXPECT_EQ(t.row.swipe_flag, "");
  }
  const ex::Presenter::UploadCounts uploads = presenter->upload_counts();
  EXPECT_EQ(uploads.uploads, 4);  // two different textures per trial, before its onset
  EXPECT_EQ(uploads.at_switch, 0);
  presenter->stop();
  presenter.reset();
  stop = true;
  loop.join();

  // At rest after stop(): nothing selected, output 0.
  EXPECT_EQ(ctl->status().selected, texel::serial::no_map);
  EXPECT_EQ(ctl->status().amplitude, 0);
  // The display holds texel render's exact samples (the last two stimuli).
  for (std::uint8_t slot = 0; slot < 2; ++slot) {
    const std::uint32_t n = ctl->map_samples(slot);
    ASSERT_EQ(n, maps.back().size());
    bool found = false;
    for (const auto& m : maps) {
      bool same = m.size() == n;
      for (std::uint32_t i = 0; same && i < n; ++i) same = ctl->map_value(slot, i) == m[i];
      found = found || same;
    }
    EXPECT_TRUE(found) << "slot " << int(slot) << " holds none of the stimuli's maps";
  }
  // …which are `texel render`'s bytes.
  texel::test_support::TempDir tmp("display-loop");
  texel::write_file_atomic(tmp.at("s.texel.json"), documents.back());
  const auto render = texel::test_support::run_cli(TEXEL_CLI, "render " + tmp.at("s.texel.json") + " -o " + tmp.at("s.bin"));
  ASSERT_EQ(render.status, 0) << render.out;
  const std::string bin = texel::read_file(tmp.at("s.bin"));
  ASSERT_EQ(bin.size(), 2 * maps.back().size());
  EXPECT_EQ(std::memcmp(bin.data(), maps.back().data(), bin.size()), 0);

  // Every output update while a stimulus was selected: the selected map's
  // sample nearest the sensed x (0 while lifted); after the blank, 0.
  std::size_t touched = 0, lifted = 0, blank = 0;
  const double spacing_nm = std::lround(texel::parse_document(documents[0]).device.spacing.value() * 1e6);
  for (const auto& u : hal.log) {
    if (u.expect == -2) continue;
    if (u.expect == -1) {
      EXPECT_EQ(u.amplitude, 0);
      ++blank;
      continue;
    }
    if (!u.touch) {
      EXPECT_EQ(u.amplitude, 0) << "driven while lifted";
      ++lifted;
      continue;
    }
    const auto& m = maps[static_cast<std::size_t>(u.expect)];
    const auto idx = static_cast<std::size_t>((u.x_nm + spacing_nm / 2) / spacing_nm);
    ASSERT_LT(idx, m.size());
    ASSERT_EQ(u.amplitude, m[idx]) << "stimulus " << u.expect << " at x " << u.x_nm * 1e-6 << " mm";
    ++touched;
  }
  EXPECT_GE(touched, 200u);
  EXPECT_GE(lifted, 10u);
  EXPECT_GE(blank, 10u);
  std::printf("display-plays: %zu output updates checked touching, %zu lifted, %zu blank; %d uploads (%d at a switch, %.3f s)\n",
              touched, lifted, blank, uploads.uploads, uploads.at_switch, uploads.seconds);
}

// `texel experiment run` against the controller as a child process whose
// sensor is the reference stroke script (`--sensor strokes`: speed varying
// from stroke to stroke, pauses, lifts; stroke_script.hpp): texel-length and
// quantization, the simulated observer answering while the display's finger
// explores. The expected measures come from the script itself, at the
// display's clock (its log gives the script's t = 0 on that clock).
TEST(DisplayLoop, StudiesRunEndToEndAndStoreTheFingerThatExplored) {
  texel::test_support::TempDir tmp("display-loop");
  texel::write_file_atomic(tmp.at("texel-length.json"), short_texel_length(3));
  texel::write_file_atomic(tmp.at("quantization.json"), short_quantization());
  texel::test_support::ControllerProcess display(
      TEXEL_CLI, {"--sensor", "strokes", "--log", tmp.at("display.csv"), "--duration", "120", "--quiet"});
  ASSERT_FALSE(display.pty().empty());
  const std::string backend = "serial:" + display.pty();
  for (const std::string study : {"texel-length", "quantization"}) {
    SCOPED_TRACE(study);
    const auto run =
        texel::test_support::run_cli(TEXEL_CLI,
                                     "experiment run " + tmp.at(study + ".json") + " --participant P1 --db " + tmp.at("s.db") +
                                         " --simulate default --pace 1.2 --backend " + backend + " --json",
                                     false);
    ASSERT_EQ(run.status, 0) << run.out;
    const json j = json::parse(run.out);
    EXPECT_EQ(j["mode"], "display-plays");
    EXPECT_TRUE(j["finished"].get<bool>());
    EXPECT_GE(j["maps_uploaded"].get<int>(), 2);
    EXPECT_GT(j["finger_reports"].get<int>(), 500);  // the display reported throughout
    // At rest after the end (the display answers a new host).
    const texel::DisplayStatus st = status_of(display.pty());
    EXPECT_EQ(st.selected, -1);
    EXPECT_EQ(st.amplitude, 0);
  }
  EXPECT_NE(display.stop().find("bad 0"), std::string::npos);
  // The script's t = 0 on the display's clock (t_us of its reports).
  const std::string log = texel::read_file(tmp.at("display.csv"));
  const std::size_t row1 = log.find('\n') + 1;
  double log_t = 0, log_us = 0;
  ASSERT_EQ(std::sscanf(log.c_str() + row1, "%lf,%lf", &log_t, &log_us), 2) << log.substr(0, 200);
  const double t0_s = log_us * 1e-6 - log_t;
  const texel::StrokeScript script{texel::StrokeScriptConfig{}};
  const auto script_measures_at = [&](const std::vector<texel::FingerSample>& trace) {
    std::vector<texel::FingerSample> s;
    for (const auto& sample : trace) {
      texel::FingerSample f = script.at(std::fmod(sample.t_s - t0_s + 4294.967296, 4294.967296));
      f.t_s = sample.t_s;
      s.push_back(f);
    }
    return texel::swipe_measures(s, ex::SwipeLimits{}.still_speed_mm_s);
  };

  const auto csv = texel::test_support::run_cli(TEXEL_CLI, "experiment export --db " + tmp.at("s.db") + " -o " + tmp.at("t.csv"));
  ASSERT_EQ(csv.status, 0) << csv.out;
  const auto rows = ex::parse_trials_csv(texel::read_file(tmp.at("t.csv")), "t.csv");
  ASSERT_EQ(rows.size(), 5u);  // 3 oddity trials, 2 ratings
  const ex::Store store = ex::Store::open(tmp.at("s.db"), ex::StoreMode::read_only);
  std::size_t i = 0;
  for (const auto& session : store.sessions())
    for (const auto& t : store.trials(session.id)) {
      const ex::TrialRow& row = rows.at(i++);
      SCOPED_TRACE(row.protocol + " trial " + std::to_string(row.trial));
      EXPECT_EQ(row.presentation_mode, "display-plays");
      EXPECT_EQ(row.finger_source, "display");
      EXPECT_EQ(t.trace.source, ex::TraceSource::display);
      ASSERT_GT(t.trace.samples.size(), 300u);  // 1.2 s of reports (a starved controller skips some)
      const texel::SwipeMeasures want = script_measures_at(t.trace.samples);
      EXPECT_GT(want.mean_speed_mm_s, 10.0);  // the script moved during the trial
      EXPECT_NEAR(row.swipe_mean_speed_mm_s, want.mean_speed_mm_s, 0.02 * want.mean_speed_mm_s);
      EXPECT_NEAR(row.swipe_sd_speed_mm_s, want.sd_speed_mm_s, 0.02 * want.sd_speed_mm_s);
      EXPECT_NEAR(row.directional_proportion, want.directional_proportion, 0.02);
      std::printf("%s trial %d: %zu reports; mean %.2f mm/s (script %.2f), SD %.2f (%.2f), directional %.3f (%.3f)\n",
                  row.protocol.c_str(), row.trial, t.trace.samples.size(), row.swipe_mean_speed_mm_s, want.mean_speed_mm_s,
                  row.swipe_sd_speed_mm_s, want.sd_speed_mm_s, row.directional_proportion, want.directional_proportion);
    }
}

// A 1-D study whose stimuli play on another backend (here the null one, as a
// sound card's actuators would) with the finger from a sensor on a link of
// its own (`--finger serial:PATH`): host-streams from the sensor's reports,
// and every trial stores that finger. What cannot work is refused with one
// line before the first trial.
TEST(DisplayLoop, AOneDStudyTakesItsFingerFromASeparateSensor) {
  texel::test_support::TempDir tmp("display-sensor");
  texel::write_file_atomic(tmp.at("p.json"), short_texel_length(3));
  texel::test_support::ControllerProcess sensor(TEXEL_CLI, {"--sensor", "strokes", "--duration", "120", "--quiet"});
  texel::test_support::ControllerProcess no_sensor(TEXEL_CLI, {"--duration", "120", "--quiet"});
  ASSERT_FALSE(sensor.pty().empty());
  ASSERT_FALSE(no_sensor.pty().empty());
  const std::string base = "experiment run " + tmp.at("p.json") + " --participant P1 --db " + tmp.at("s.db") + " ";
  const auto run = [&](const std::string& extra) { return texel::test_support::run_cli(TEXEL_CLI, base + extra, false); };
  const auto refused = [&](const std::string& extra, const std::string& why) {
    const auto r = texel::test_support::run_cli(TEXEL_CLI, base + extra);
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find(why), std::string::npos) << r.out;
  };
  refused("--simulate default --finger serial:" + no_sensor.pty(), "does not report the finger");
  refused("--simulate default --backend serial:" + sensor.pty() + " --finger serial:" + sensor.pty(),
          "is the backend's own display");
  refused("--simulate default --finger serial:" + sensor.pty() + " --mode display-plays", "give --mode host-streams");
  refused("--simulate default --finger usb:1", "allowed: serial:PATH");
  EXPECT_FALSE(std::filesystem::exists(tmp.at("s.db"))) << "a refused run stores nothing";

  const auto r = run("--simulate default --pace 1.2 --backend null --finger serial:" + sensor.pty() + " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["mode"], "host-streams");
  EXPECT_TRUE(j["finished"].get<bool>());
  EXPECT_GT(j["finger_reports"].get<int>(), 500);
  EXPECT_NE(j["backend"].get<std::string>().find("from the finger sensor " + sensor.pty()), std::string::npos);
  const ex::Store store = ex::Store::open(tmp.at("s.db"), ex::StoreMode::read_only);
  const auto rows = store.rows(store.sessions().at(0).id);
  ASSERT_EQ(rows.size(), 3u);
  for (const ex::TrialRow& row : rows) {
    EXPECT_EQ(row.presentation_mode, "host-streams");
    EXPECT_EQ(row.finger_source, "display");
    EXPECT_EQ(row.swipe_flag, "");
    EXPECT_GT(row.swipe_mean_speed_mm_s, 5.0);  // the stroke script's, not a simulated sweep's 100 mm/s
  }
  EXPECT_NE(sensor.stop().find("bad 0"), std::string::npos);
}

// Every way a run ends leaves the display at rest (STATUS from a new host):
// 'q' at the terminal, Ctrl-C, SIGTERM and an error (another process took
// the session's writer lock), in display-plays and in drive mode.
TEST(DisplayLoop, EveryExitLeavesTheDisplayAtRest) {
  texel::test_support::TempDir tmp("display-loop");
  texel::write_file_atomic(tmp.at("strokes.csv"), script_csv);
  texel::write_file_atomic(tmp.at("p.json"), short_texel_length(10));
  texel::test_support::ControllerProcess display(
      TEXEL_CLI, {"--sensor", tmp.at("strokes.csv"), "--sensor-lift", "0.15", "--duration", "120", "--quiet"});
  ASSERT_FALSE(display.pty().empty());
  const std::string backend = "serial:" + display.pty();
  int participant = 0;
  // Starts a run in the background; returns its pid.
  auto start = [&](const std::string& extra, const std::string& input) {
    const std::string who = "P" + std::to_string(++participant);
    const pid_t pid = ::fork();
    if (pid == 0) {
      const std::string cmd = input + std::string(TEXEL_CLI) + " experiment run " + tmp.at("p.json") + " --participant " + who +
                              " --db " + tmp.at("s.db") + " --backend " + backend + " --monitor " + tmp.at(who + ".txt") + " " +
                              extra + " >" + tmp.at(who + ".out") + " 2>&1";
      // Without input, exec: the signals the test sends reach texel itself.
      ::execl("/bin/sh", "sh", "-c", ((input.empty() ? "exec " : "") + cmd).c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    return pid;
  };
  auto exit_status = [](pid_t pid) {
    int s = 0;
    ::waitpid(pid, &s, 0);
    return WIFEXITED(s) ? WEXITSTATUS(s) : 128 + WTERMSIG(s);
  };
  // Rest: nothing selected, output 0; after a clean exit also out of drive
  // mode (after SIGKILL the display's watchdog zeroes a drive that stays).
  auto at_rest = [&](const std::string& how, bool clean = true) {
    SCOPED_TRACE(how);
    const texel::DisplayStatus st = status_of(display.pty());
    EXPECT_EQ(st.selected, -1);
    EXPECT_EQ(st.amplitude, 0);
    if (clean) {
      EXPECT_NE(st.mode, 2) << "left in drive mode";
    }
  };
  // 'q' after feeling texture 2.
  {
    const pid_t pid = start("", "(sleep 1.0; echo 2; sleep 0.8; echo q) | ");
    EXPECT_EQ(exit_status(pid), 0);
    at_rest("q");
    EXPECT_NE(texel::read_file(tmp.at("P1.txt")).find(" play "), std::string::npos);  // it was playing
    // The resume line repeats the display (a resume on the null backend would be silent).
    const std::string out = texel::read_file(tmp.at("P1.out"));
    EXPECT_NE(out.find("--participant P1 --db " + tmp.at("s.db") + " --backend " + backend + " --monitor " + tmp.at("P1.txt") +
                       " --resume"),
              std::string::npos)
        << out;
  }
  // Ctrl-C and SIGTERM mid-trial, display-plays and drive (host-streams).
  for (const std::string mode : {"display-plays", "host-streams"})
    for (const int sig : {SIGINT, SIGTERM}) {
      const pid_t pid = start("--simulate default --pace 3 --mode " + mode, "");
      std::this_thread::sleep_for(2500ms);
      ::kill(pid, sig);
      EXPECT_EQ(exit_status(pid), 0);
      at_rest(mode + " signal " + std::to_string(sig));
    }
  // kill -9 in drive mode: nothing can be sent; the display rests by itself
  // (its watchdog, or the link's loss) within 200 ms.
  {
    const pid_t pid = start("--simulate default --pace 3 --mode host-streams", "");
    std::this_thread::sleep_for(2500ms);
    ::kill(pid, SIGKILL);
    EXPECT_EQ(exit_status(pid), 128 + SIGKILL);
    std::this_thread::sleep_for(200ms);
    at_rest("kill -9, drive mode", false);
  }
  // An error mid-run: another process takes the writer lock; the run stops with exit 2.
  {
    const pid_t pid = start("--simulate default --pace 1.5", "");
    std::this_thread::sleep_for(2000ms);
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(tmp.at("s.db").c_str(), &db), SQLITE_OK);
    sqlite3_busy_timeout(db, 5000);
    ASSERT_EQ(sqlite3_exec(db, "UPDATE writers SET pid = 1, process_start = 1", nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
    EXPECT_EQ(exit_status(pid), 2);
    at_rest("error");
    EXPECT_NE(texel::read_file(tmp.at("P" + std::to_string(participant) + ".out")).find("writer lock"), std::string::npos);
  }
}
