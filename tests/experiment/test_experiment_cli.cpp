// The acceptance checks of issue #8 on the built CLI: simulated runs,
// export (one row per trial), analyze (convergent value + staircase figure),
// a paced run SIGKILLed at random moments and resumed (nothing lost, nothing
// duplicated, the same data as an uninterrupted run), a second writer, bad
// input (exit 2, one line, nothing stored touched), and the audio backend
// through a real PortAudio stream on an ALSA null PCM.
#include <fcntl.h>
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include "../support/cli_run.hpp"
#include "../support/controller_process.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "texel/experiment/records.hpp"
#include "texel/io.hpp"

namespace ex = texel::experiment;
namespace fs = std::filesystem;
using texel::test_support::TempDir;

namespace {

const std::string protocols = std::string(TEXEL_TEST_SOURCE_DIR) + "/examples/protocols/";

using texel::test_support::CliRun;
CliRun run(const std::string& args, const std::string& env = "") {
  return texel::test_support::run_cli(TEXEL_CLI, args, true, env);
}

// The export without its wall-clock columns: what must be equal between an
// interrupted and an uninterrupted run.
std::vector<std::string> stable_rows(const std::string& csv_path) {
  auto rows = ex::parse_trials_csv(texel::read_file(csv_path), csv_path);
  std::vector<std::string> out;
  for (auto& r : rows) {
    r.shown_at.clear();
    r.answered_at.clear();
    r.session_id = 0;
    out.push_back(ex::csv_line(r));
  }
  return out;
}

std::size_t lines(const std::string& text) { return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')); }

}  // namespace

TEST(ExperimentCli, TexelLengthSimulatedExportAnalyze) {
  TempDir d("texel-exp-cli");
  const std::string db = d.at("s.db");
  const CliRun r =
      run("experiment run " + protocols + "texel-length.json --participant S01 --db " + db + " --simulate threshold=6mm --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto summary = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  EXPECT_TRUE(summary["finished"].get<bool>());
  EXPECT_EQ(summary["response"], "limit");  // the protocol device's response, respected by default
  const int trials = summary["trials"].get<int>();
  EXPECT_GT(trials, 10);

  const CliRun e = run("experiment export --db " + db + " -o " + d.at("results.csv"));
  ASSERT_EQ(e.status, 0) << e.out;
  const std::string csv = texel::read_file(d.at("results.csv"));
  EXPECT_EQ(lines(csv), static_cast<std::size_t>(trials) + 1);  // header + one row per trial
  EXPECT_EQ(csv.rfind("participant,session_id,protocol", 0), 0u);

  const CliRun a = run("experiment analyze --db " + db + " --json -o " + d.at("fig"));
  ASSERT_EQ(a.status, 0) << a.out;
  EXPECT_NE(a.out.find("convergent"), std::string::npos) << a.out;
  bool staircase_figure = false;
  for (const auto& f : fs::directory_iterator(d.at("fig")))
    staircase_figure |= f.path().filename().string().find("tracks") != std::string::npos;
  EXPECT_TRUE(staircase_figure);

  // The same analysis from the exported CSV.
  EXPECT_EQ(run("experiment analyze --csv " + d.at("results.csv") + " --json").status, 0);
  const CliRun l = run("experiment list --db " + db);
  EXPECT_EQ(l.status, 0);
  EXPECT_NE(l.out.find("finished"), std::string::npos);
  EXPECT_EQ(run("experiment status --db " + db + " --json").status, 0);
}

TEST(ExperimentCli, GuidedExplorationStoresTwentyComparisonsPerReference) {
  TempDir d("texel-exp-cli");
  const std::string db = d.at("s.db");
  const CliRun r = run("experiment run " + protocols + "guided-exploration.json --participant S02 --db " + db +
                       " --simulate target=4sin --quiet");
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_EQ(run("experiment export --db " + db + " -o " + d.at("g.csv")).status, 0);
  const auto rows = ex::parse_trials_csv(texel::read_file(d.at("g.csv")), "g.csv");
  std::map<std::string, int> per_ref;
  int finished = 0;
  for (const auto& row : rows) {
    if (row.task != "guided") continue;
    ++per_ref[row.reference];
    if (row.procedure_finished) {
      ++finished;
      EXPECT_TRUE(std::isfinite(row.pitch_db));
      EXPECT_TRUE(std::isfinite(row.irregularity_db));
    }
  }
  ASSERT_EQ(per_ref.size(), 3u);
  for (const auto& [ref, n] : per_ref) EXPECT_EQ(n, 20) << ref;
  EXPECT_EQ(finished, 3);
}

TEST(ExperimentCli, KilledAtRandomMomentsAndResumedEqualsUninterrupted) {
  TempDir d("texel-exp-kill");
  const std::string proto = protocols + "texel-length.json";
  using Clock = std::chrono::steady_clock;
  auto ms_since = [](Clock::time_point t) {
    return static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t).count());
  };
  // Reference: the uninterrupted run, paced like the killed ones, and timed:
  // kill moments are set from this build's own speed (an AddressSanitizer
  // build starts and runs several times slower), never from fixed numbers.
  const auto t_run = Clock::now();
  ASSERT_EQ(run("experiment run " + proto + " --participant K1 --db " + d.at("ref.db") +
                " --simulate threshold=6mm --pace 0.01 --quiet")
                .status,
            0);
  const int run_ms = ms_since(t_run);
  ASSERT_EQ(run("experiment export --db " + d.at("ref.db") + " -o " + d.at("ref.csv")).status, 0);
  const auto expected = stable_rows(d.at("ref.csv"));
  const auto t_start = Clock::now();
  (void)run("experiment status --db " + d.at("ref.db") + " --json");
  const int startup_ms = std::min(ms_since(t_start), run_ms / 2);
  // Each attempt lives past start-up and then at most an eighth of the
  // run's work, so the run cannot finish before several kills.
  const int work_ms = std::max(run_ms - startup_ms, 80);
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> delay_ms(startup_ms + work_ms / 50, startup_ms + work_ms / 8);
  const std::string db = d.at("kill.db");
  int kills = 0;
  // What a researcher does after a crash: resume the running session; start
  // one if the kill came before it existed; stop once it is finished (a kill
  // can land after the last commit, before the process exits).
  int trials_done = 0;  // as of the last session_state()
  auto session_state = [&]() -> std::string {
    const CliRun s = run("experiment status --db " + db + " --json");
    if (s.status != 0) return "none";
    const auto j = nlohmann::json::parse(s.out.substr(s.out.find('{')));
    if (j["sessions"].empty()) return "none";
    trials_done = j["sessions"][0]["trials_done"].get<int>();
    return j["sessions"][0]["status"].get<std::string>();
  };
  // An attempt killed before it stored a trial (a slow start on a loaded
  // machine) lengthens the next ones by half, so every run makes progress.
  double stretch = 1.0;
  int trials_before = -1;
  for (int attempt = 0; attempt < 60; ++attempt) {
    const std::string state = session_state();
    if (state == "finished") break;
    if (attempt > 0 && trials_done <= trials_before) stretch = std::min(stretch * 1.5, 8.0);
    trials_before = trials_done;
    const bool first = state == "none";
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const int devnull = ::open("/dev/null", O_RDWR);
      ::dup2(devnull, 0);
      ::dup2(devnull, 1);
      ::dup2(devnull, 2);
      std::vector<std::string> args = {TEXEL_CLI, "experiment", "run",           proto,    "--participant", "K1",     "--db",
                                       db,        "--simulate", "threshold=6mm", "--pace", "0.01",          "--quiet"};
      if (!first) args.push_back("--resume");
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(TEXEL_CLI, argv.data());
      ::_exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<int>(stretch * delay_ms(rng))));
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      ASSERT_TRUE(WIFEXITED(status));
      ASSERT_EQ(WEXITSTATUS(status), 0) << "run finished with an error at attempt " << attempt;
      break;  // it completed before the kill
    }
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
    ++kills;
  }
  EXPECT_GE(kills, 5);
  std::cout << "SIGKILLed " << kills << " times at random moments\n";
  // Finish whatever is left (or start it, if every kill came before the
  // session existed).
  const std::string left = session_state();
  if (left != "finished") {
    ASSERT_EQ(run("experiment run " + proto + " --participant K1 --db " + db + " --simulate threshold=6mm --quiet" +
                  (left == "none" ? "" : " --resume"))
                  .status,
              0);
  }
  ASSERT_EQ(run("experiment export --db " + db + " -o " + d.at("kill.csv")).status, 0);
  const auto got = stable_rows(d.at("kill.csv"));
  ASSERT_EQ(got.size(), expected.size()) << "kills: " << kills;
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i]) << "trial " << i;
}

TEST(ExperimentCli, ResumeContinuesAtTheNextTrialAndSecondWriterIsRefused) {
  TempDir d("texel-exp-writer");
  const std::string proto = protocols + "working-memory.json";
  const std::string db = d.at("w.db");
  // A paced run in the background; while it runs, a second writer is refused.
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int devnull = ::open("/dev/null", O_RDWR);
    ::dup2(devnull, 0);
    ::dup2(devnull, 1);
    ::dup2(devnull, 2);
    ::execl(TEXEL_CLI, TEXEL_CLI, "experiment", "run", proto.c_str(), "--participant", "W1", "--db", db.c_str(), "--simulate",
            "default", "--pace", "0.2", "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Wait for a few stored trials.
  int done = 0;
  for (int i = 0; i < 200 && done < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto s = run("experiment status --db " + db + " --json");
    if (s.status == 0) {
      const auto j = nlohmann::json::parse(s.out.substr(s.out.find('{')));
      if (!j["sessions"].empty()) done = j["sessions"][0]["trials_done"].get<int>();
    }
  }
  ASSERT_GE(done, 3);
  const CliRun second = run("experiment run " + proto + " --participant W1 --db " + db + " --simulate default --resume");
  EXPECT_EQ(second.status, 2) << second.out;
  EXPECT_NE(second.out.find("is being written by process"), std::string::npos) << second.out;
  EXPECT_EQ(lines(second.out), 1u) << second.out;
  ::kill(pid, SIGKILL);
  int st = 0;
  ::waitpid(pid, &st, 0);
  // Starting anew beside the unfinished session is refused, and the refusal says how to resume (the CLI's flag).
  const CliRun anew = run("experiment run " + proto + " --participant W1 --db " + db + " --simulate default");
  EXPECT_EQ(anew.status, 2) << anew.out;
  EXPECT_NE(anew.out.find("has an unfinished 'working-memory' session"), std::string::npos) << anew.out;
  EXPECT_NE(anew.out.find("resume it (--resume)"), std::string::npos) << anew.out;
  const CliRun nothing = run("experiment run " + proto + " --participant W2 --db " + db + " --simulate default --resume");
  EXPECT_EQ(nothing.status, 2) << nothing.out;
  EXPECT_NE(nothing.out.find("no unfinished 'working-memory' session"), std::string::npos) << nothing.out;
  EXPECT_NE(nothing.out.find("(start one without --resume)"), std::string::npos) << nothing.out;
  const auto before = nlohmann::json::parse(run("experiment status --db " + db + " --json").out);
  const int stored = before["sessions"][0]["trials_done"].get<int>();
  const CliRun resumed = run("experiment run " + proto + " --participant W1 --db " + db + " --simulate default --resume --json");
  ASSERT_EQ(resumed.status, 0) << resumed.out;
  const auto after = nlohmann::json::parse(run("experiment status --db " + db + " --json").out);
  EXPECT_EQ(after["sessions"][0]["trials_done"].get<int>(), 41);  // the familiarisation, 8 training and 32 test trials
  EXPECT_EQ(after["sessions"][0]["status"], "finished");
  EXPECT_GT(41, stored);
  // Starting again without --resume: the finished session stays, a new one starts.
  EXPECT_EQ(run("experiment list --db " + db + " --json").status, 0);
}

TEST(ExperimentCli, TerminalRunnerTakesKeyAnswersAndSavesOnEndOfInput) {
  TempDir d("texel-exp-terminal");
  const std::string db = d.at("t.db");
  // A participant feels stimuli 1 and 3, answers "3", makes a typo, answers
  // "2" twice, then the input ends: three trials stored, session resumable.
  const std::string answers = d.write("answers.txt", "f 1\nf 3\na 3\nhello\na 7\na 2\nf 2\na 2\n");
  const std::string cmd = std::string(TEXEL_CLI) + " experiment run " + protocols + "texel-length.json --participant T1 --db " +
                          db + " < " + answers + " > " + d.at("out.txt") + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << texel::read_file(d.at("out.txt"));
  const std::string out = texel::read_file(d.at("out.txt"));
  EXPECT_NE(out.find("not a valid answer"), std::string::npos) << out;  // "a 7"
  EXPECT_NE(out.find("--resume"), std::string::npos) << out;
  ASSERT_EQ(run("experiment export --db " + db + " -o " + d.at("t.csv")).status, 0);
  const auto rows = ex::parse_trials_csv(texel::read_file(d.at("t.csv")), "t.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].response, "3");
  EXPECT_EQ(rows[1].response, "2");
  EXPECT_TRUE(std::isfinite(rows[0].rt_ms));
  EXPECT_EQ(rows[0].intensity, 26.0);
  const auto status = nlohmann::json::parse(run("experiment status --db " + db + " --json").out);
  EXPECT_EQ(status["sessions"][0]["status"], "running");
  // The one vocabulary (session_state.hpp): unfinished and held by nobody = stopped, in JSON and text alike.
  EXPECT_EQ(status["sessions"][0]["state"], "stopped");
  EXPECT_NE(run("experiment status --db " + db).out.find("[stopped]"), std::string::npos);
  EXPECT_NE(run("experiment list --db " + db).out.find(" stopped "), std::string::npos);
}

TEST(ExperimentCli, BadInputIsOneLineExitTwoAndTouchesNothing) {
  TempDir d("texel-exp-bad");
  const std::string db = d.at("s.db");
  auto one_line_2 = [](const CliRun& r) {
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_EQ(lines(r.out), 1u) << r.out;
  };
  const std::string bad =
      d.write("bad.json", R"({"format": "texel-protocol", "version": 1, "name": "x", "study": "nosuch", "blocks": []})");
  one_line_2(run("experiment run " + bad + " --participant S01 --db " + db + " --simulate default"));
  EXPECT_FALSE(fs::exists(db));
  one_line_2(
      run("experiment run " + protocols + "texel-length.json --participant 'John Smith' --db " + db + " --simulate default"));
  one_line_2(run("experiment run " + protocols + "texel-length.json --participant S01 --db " + db + " --simulate colour=red"));
  one_line_2(
      run("experiment run " + protocols + "texel-length.json --participant S01 --db " + db + " --resume --simulate default"));
  one_line_2(run("experiment run " + protocols + "texel-length.json --participant S01 --db " + db +
                 " --backend laser --simulate default"));
  one_line_2(run("experiment run " + protocols + "texel-length.json --participant S01 --db " + db +
                 " --response equalize --simulate default"));
  EXPECT_FALSE(fs::exists(db));
  one_line_2(run("experiment export --db " + d.at("missing.db") + " -o " + d.at("x.csv")));
  EXPECT_FALSE(fs::exists(d.at("x.csv")));
  // A corrupt database is refused and left byte-identical.
  const std::string corrupt = d.write("corrupt.db", std::string(4096, 'x'));
  one_line_2(run("experiment run " + protocols + "texel-length.json --participant S01 --db " + corrupt + " --simulate default"));
  one_line_2(run("experiment list --db " + corrupt));
  EXPECT_EQ(texel::read_file(corrupt), std::string(4096, 'x'));
  // An unfinished session is not silently restarted.
  ASSERT_EQ(
      run("experiment run " + protocols + "coarse-features.json --participant S01 --db " + db + " --simulate default --quiet")
          .status,
      0);
  one_line_2(run("experiment analyze --db " + db + " --csv x.csv"));
}

TEST(ExperimentCli, SerialFrictionDisplayThroughTheReferenceController) {
  // The reference display controller on a pseudo-terminal stands in for a
  // friction display; the study streams drive values to it.
  TempDir d("texel-exp-serial");
  texel::test_support::ControllerProcess ctl(TEXEL_CLI, {"--duration", "120", "--quiet"});
  ASSERT_FALSE(ctl.pty().empty());
  const CliRun r = run("experiment run " + protocols + "coarse-features.json --participant D1 --db " + d.at("d.db") +
                       " --simulate default --pace 0.005 --backend serial:" + ctl.pty() + " --json");
  const std::string rest = ctl.stop();
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  EXPECT_TRUE(j["finished"].get<bool>());
  EXPECT_GT(j["blocks_processed"].get<double>(), 50);
  EXPECT_EQ(j["late_blocks"].get<double>(), 0);
  // No sensor: no finger explores, so the stimuli play under the simulated sweep, labelled passive.
  EXPECT_EQ(j["mode"], "passive");
  // The controller took every frame the study sent: none bad, no link error;
  // one NACK, its answer to the host asking for finger reports (no_sensor).
  EXPECT_NE(rest.find("bad 0, nacks 1, link errors 0"), std::string::npos) << rest;
}

TEST(ExperimentCli, AudioBackendThroughPortAudioOnAnAlsaNullPcm) {
  // A real PortAudio stream with no sound card: ALSA's default device is a
  // `null` PCM defined by this test's own configuration file.
  TempDir d("texel-exp-audio");
  const std::string conf = d.write("asound.conf", "pcm.!default { type null }\nctl.!default { type hw card 0 }\n");
  const std::string env = "ALSA_CONFIG_PATH=" + conf;
  const CliRun r = run("experiment run " + protocols + "coarse-features.json --participant A1 --db " + d.at("a.db") +
                           " --simulate default --pace 0.01 --backend audio --json",
                       env);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  EXPECT_TRUE(j["finished"].get<bool>());
  EXPECT_GT(j["blocks_processed"].get<double>(), 10);
  EXPECT_GT(j["stimuli_shown"].get<double>(), 10);
  std::cout << "audio backend: " << j["backend"] << ", blocks " << j["blocks_processed"] << ", worst block "
            << j["worst_block_ms"] << " ms (" << j["worst_block_fraction"] << " of the period), late blocks " << j["late_blocks"]
            << "\n";
}
