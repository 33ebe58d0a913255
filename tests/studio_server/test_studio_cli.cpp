// `texel studio` as a user runs it: the printed address, the page, a
// WebSocket `hello` to the real Service, SIGTERM → exit 0; bad flags and
// addresses → exit 2; and the real server abused (malformed JSON, unknown
// types, binary and oversized frames, floods, resets) while an experiment
// session runs, after which the store holds exactly the answered trials
// and the session resumes at the next one. The CLI built with a test-only
// task kind (texel_with_test_kind) runs that kind through its studio.
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/temp_dir.hpp"
#include "client.hpp"
#include "texel/experiment/store.hpp"
#include "texel/io.hpp"

extern char** environ;

namespace {

using namespace std::chrono_literals;
using nlohmann::json;
using texel::test_support::TempDir;
using texel::test_support::WsClient;
using Clock = std::chrono::steady_clock;

// `texel studio ARGS` with stdout and stderr on pipes.
struct Studio {
  pid_t pid = -1;
  int out = -1, err = -1;
  std::uint16_t port = 0;
  std::string first_line;

  // `program` is the texel CLI to run (TEXEL_CLI, or a test build of it).
  explicit Studio(const std::vector<std::string>& args, const char* program = TEXEL_CLI) {
    int out_pipe[2], err_pipe[2];
    if (::pipe(out_pipe) != 0 || ::pipe(err_pipe) != 0) return;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out_pipe[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, err_pipe[1], STDERR_FILENO);
    posix_spawn_file_actions_addclose(&actions, out_pipe[0]);
    posix_spawn_file_actions_addclose(&actions, err_pipe[0]);
    std::vector<std::string> all{program, "studio"};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (::posix_spawn(&pid, program, &actions, nullptr, argv.data(), environ) != 0) pid = -1;
    posix_spawn_file_actions_destroy(&actions);
    ::close(out_pipe[1]);
    ::close(err_pipe[1]);
    out = out_pipe[0];
    err = err_pipe[0];
    first_line = read_line(out);
    const std::string prefix = "Texel Studio at http://";
    if (first_line.rfind(prefix, 0) == 0) {
      const auto colon = first_line.rfind(':');
      port = static_cast<std::uint16_t>(std::stoi(first_line.substr(colon + 1)));
    }
  }
  ~Studio() {
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
    ::close(out);
    ::close(err);
  }

  // One line from `fd` ("" on end of output or after `timeout`).
  static std::string read_line(int fd, std::chrono::milliseconds timeout = 10s) {
    std::string line;
    const auto deadline = Clock::now() + timeout;
    char c = 0;
    while (Clock::now() < deadline) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;
      if (::read(fd, &c, 1) != 1 || c == '\n') break;
      line += c;
    }
    return line;
  }

  // Sends SIGTERM and returns the exit status (-1: killed or did not exit in time).
  int terminate(std::chrono::milliseconds timeout = 10s) {
    ::kill(pid, SIGTERM);
    const auto deadline = Clock::now() + timeout;
    int status = 0;
    while (Clock::now() < deadline) {
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        pid = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(10ms);
    }
    return -1;
  }
};

std::string web_root(const TempDir& dir) {
  std::filesystem::create_directories(dir.path / "web");
  std::ofstream(dir.path / "web" / "index.html") << "<!doctype html><title>studio</title>";
  return (dir.path / "web").string();
}

// The next reply, parsed (null after a close or timeout).
json read_json(WsClient& c, std::chrono::milliseconds timeout = 10s) {
  const auto text = c.read(timeout);
  return text ? json::parse(*text, nullptr, false) : json();
}

// The next reply, skipping the session state the service pushes to every
// client (id null, type experiment.*; docs/studio.md "The token rule").
json read_reply(WsClient& c, std::chrono::milliseconds timeout = 10s) {
  while (true) {
    json j = read_json(c, timeout);
    const bool pushed =
        j.is_object() && j.contains("id") && j["id"].is_null() && j.value("type", "").rfind("experiment.", 0) == 0;
    if (!pushed) return j;
  }
}

TEST(StudioCli, ServesThePageAndTheServiceAndStopsCleanlyOnSigterm) {
  TempDir dir("texel-studio-cli");
  Studio studio({"--port", "0", "--web", web_root(dir), "--db", dir.at("s.db")});
  ASSERT_NE(studio.port, 0) << "first line: " << studio.first_line;
  EXPECT_EQ(studio.first_line, "Texel Studio at http://127.0.0.1:" + std::to_string(studio.port) + "/");

  const auto page = texel::test_support::http_request(studio.port, "GET", "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_EQ(page.body, "<!doctype html><title>studio</title>");

  WsClient c;
  ASSERT_TRUE(c.connect(studio.port, "/ws", "http://127.0.0.1:" + std::to_string(studio.port))) << c.error();
  ASSERT_TRUE(c.send_text(R"({"type":"hello","id":1})"));
  const json hello = read_json(c);
  EXPECT_EQ(hello.value("type", ""), "hello") << hello.dump().substr(0, 200);
  EXPECT_EQ(hello.value("id", 0), 1);

  EXPECT_EQ(studio.terminate(), 0);
  EXPECT_EQ(c.read(), std::nullopt);
  EXPECT_EQ(c.close_code(), 1001) << "going away";
}

TEST(StudioCli, BadFlagsAddressesAndMissingFrontEndsExitWithTwo) {
  TempDir dir("texel-studio-cli");
  const std::string web = web_root(dir);
  const std::string cli = TEXEL_CLI;
  struct Case {
    std::string args, says;
  };
  const Case cases[] = {
      {"studio --port 70000 --web " + web, "--port"},
      {"studio --port abc --web " + web, "--port"},
      {"studio --bogus", "--bogus"},
      {"studio --port 0 --web " + dir.at("nowhere"), "make demo"},
      {"studio --port 0 --address 0.0.0.0 --web " + web, "--allow-remote"},
      {"studio --port 0 --address localhost --web " + web, "not an IP address"},
      {"studio --port 0 --backend warp --web " + web + " --db " + dir.at("s.db"), "warp"},
  };
  for (const auto& c : cases) {
    const auto r = texel::test_support::run_cli(cli, c.args);
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.says), std::string::npos) << c.args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line: " << r.out;
  }
  // A port in use.
  Studio first({"--port", "0", "--web", web, "--db", dir.at("a.db")});
  ASSERT_NE(first.port, 0);
  const auto busy = texel::test_support::run_cli(
      cli, "studio --port " + std::to_string(first.port) + " --web " + web + " --db " + dir.at("b.db"));
  EXPECT_EQ(busy.status, 2) << busy.out;
  EXPECT_NE(busy.out.find("cannot listen on 127.0.0.1:" + std::to_string(first.port)), std::string::npos) << busy.out;
  EXPECT_EQ(first.terminate(), 0);
}

TEST(StudioCli, AllowRemoteServesWithAWarning) {
  TempDir dir("texel-studio-cli");
  Studio studio({"--port", "0", "--address", "0.0.0.0", "--allow-remote", "--web", web_root(dir), "--db", dir.at("s.db")});
  ASSERT_NE(studio.port, 0) << studio.first_line;
  EXPECT_EQ(studio.first_line, "Texel Studio at http://0.0.0.0:" + std::to_string(studio.port) + "/");
  const std::string warning = Studio::read_line(studio.err);
  EXPECT_NE(warning.find("warning: serving on 0.0.0.0"), std::string::npos) << warning;
  EXPECT_EQ(texel::test_support::http_request(studio.port, "GET", "/").status, 200);
  EXPECT_EQ(studio.terminate(), 0);
}

TEST(StudioCli, AbuseDuringASessionLeavesTheStoredTrialsIntact) {
  TempDir dir("texel-studio-cli");
  const std::string web = web_root(dir), db = dir.at("s.db");
  constexpr int answered = 6;
  std::int64_t session_id = 0;
  {
    Studio studio({"--port", "0", "--web", web, "--db", db});
    ASSERT_NE(studio.port, 0) << studio.first_line;
    WsClient experimenter;
    ASSERT_TRUE(experimenter.connect(studio.port));
    ASSERT_TRUE(experimenter.send_text(
        R"({"type":"experiment.start","id":"s","protocol":"texel-length","participant":"P01","simulate":"default"})"));
    const json started = read_json(experimenter);
    ASSERT_EQ(started.value("type", ""), "experiment.started") << started.dump();
    session_id = started["session"]["id"].get<std::int64_t>();

    // Hostile clients, all at once, while the session is answered.
    std::thread abusers([&] {
      WsClient flood;
      if (!flood.connect(studio.port)) return;
      const std::string state = R"({"type":"feel.state"})";
      for (int i = 0; i < 5000; ++i) flood.send_raw(texel::test_support::ws_frame_header(state.size()) + state);
      const std::string nasty[] = {
          "not json",
          "{",
          "[]",
          "null",
          R"({"type":"no.such.type"})",
          R"({"type":"experiment.answer","trial":99999,"simulated":true})",
          R"({"type":"experiment.answer","trial":"x","response":{"choice":"A"}})",
          R"({"type":"experiment.stop","extra":1})",
          R"({"type":"experiment.start","protocol":{"name":"evil"},"participant":"P01"})",
          std::string(100000, '[') + std::string(100000, ']'),
          R"({"type":"hello","id":")" + std::string(1000, 'x') + "\"}",
      };
      WsClient rude;
      if (!rude.connect(studio.port)) return;
      for (int round = 0; round < 20; ++round)
        for (const auto& m : nasty) {
          rude.send_text(m);
          const json reply = read_reply(rude);
          EXPECT_EQ(reply.value("type", ""), "error") << m.substr(0, 80) << " → " << reply.dump().substr(0, 200);
        }
      rude.send_binary("binary");
      EXPECT_EQ(read_reply(rude).value("code", ""), "bad_message");
      for (int i = 0; i < 20; ++i) {
        WsClient reset;
        if (!reset.connect(studio.port)) continue;
        reset.send_raw(texel::test_support::ws_frame_header(1u << 20) + std::string(1000, '{'));
        reset.reset();
      }
      WsClient big;
      if (big.connect(studio.port)) {
        big.send_text(std::string((4u << 20) + 1, ' '));
        big.read(2s);
      }
    });

    int trial = started["progress"]["done"].get<int>();
    for (int i = 0; i < answered; ++i) {
      ASSERT_TRUE(
          experimenter.send_text(R"({"type":"experiment.answer","simulated":true,"trial":)" + std::to_string(trial) + "}"));
      const json next = read_json(experimenter);
      ASSERT_EQ(next.value("type", ""), "experiment.question") << next.dump().substr(0, 300);
      EXPECT_EQ(next["progress"]["done"].get<int>(), i + 1);
      trial = next["question"]["trial"].get<int>();
    }
    abusers.join();
    // Still serving everyone.
    WsClient after;
    ASSERT_TRUE(after.connect(studio.port));
    ASSERT_TRUE(after.send_text(R"({"type":"experiment.current"})"));
    const json current = read_json(after);
    EXPECT_EQ(current.value("type", ""), "experiment.question") << current.dump().substr(0, 300);
    EXPECT_EQ(current["progress"]["done"].get<int>(), answered);
    after.close();
    experimenter.close();
    EXPECT_EQ(studio.terminate(), 0);
  }

  {
    const auto store = texel::experiment::Store::open(db, texel::experiment::StoreMode::read_only);
    const auto trials = store.trials(session_id);
    ASSERT_EQ(static_cast<int>(trials.size()), answered);
    EXPECT_EQ(store.sessions().size(), 1u) << "the hostile start created no session";
  }

  // Restarted, the session resumes at the next trial.
  Studio again({"--port", "0", "--web", web, "--db", db});
  ASSERT_NE(again.port, 0);
  WsClient experimenter;
  ASSERT_TRUE(experimenter.connect(again.port));
  ASSERT_TRUE(
      experimenter.send_text(R"({"type":"experiment.start","protocol":"texel-length","participant":"P01","resume":true})"));
  const json resumed = read_json(experimenter);
  ASSERT_EQ(resumed.value("type", ""), "experiment.started") << resumed.dump();
  EXPECT_EQ(resumed["progress"]["done"].get<int>(), answered);
  experimenter.close();
  EXPECT_EQ(again.terminate(), 0);
}

#ifdef TEXEL_WITH_TEST_KIND
// The test-only task kind (tests/experiment/press_side_task.cpp) through the
// real studio: `texel_with_test_kind studio` (the shipped CLI's objects plus
// that one file) runs its protocol over the WebSocket to the end, and the
// same program's `experiment export` writes its trials.
TEST(StudioCli, TestOnlyTaskKindRunsThroughTheStudioProgram) {
  TempDir dir("texel-studio-task-kind");
  const std::string db = dir.at("s.db");
  const json protocol =
      json::parse(texel::read_file(std::string(TEXEL_TEST_SOURCE_DIR) + "/tests/experiment/data/press-side.json"));
  Studio studio({"--port", "0", "--web", web_root(dir), "--db", db}, TEXEL_WITH_TEST_KIND);
  ASSERT_NE(studio.port, 0) << studio.first_line;
  WsClient client;
  ASSERT_TRUE(client.connect(studio.port));
  int next_id = 1;
  auto ask = [&](json msg) {
    const int id = next_id++;
    msg["id"] = id;
    EXPECT_TRUE(client.send_text(msg.dump()));
    while (true) {
      const json j = read_json(client, 30s);
      if (!j.is_object() || j.value("id", json()) == json(id)) return j;
    }
  };
  const json started =
      ask({{"type", "experiment.start"}, {"protocol", protocol}, {"participant", "P01"}, {"simulate", "default"}});
  ASSERT_EQ(started.value("type", ""), "experiment.started") << started.dump().substr(0, 300);
  EXPECT_EQ(started["progress"]["planned"], 7);
  json q = ask({{"type", "experiment.current"}});
  int answered = 0;
  while (q.value("type", "") == "experiment.question" && answered < 20) {
    EXPECT_EQ(q["question"]["task"], "press-side");
    EXPECT_EQ(q["question"]["choices"], json({"left", "right"}));
    q = ask({{"type", "experiment.answer"}, {"trial", q["question"]["trial"]}, {"simulated", true}});
    ++answered;
  }
  EXPECT_EQ(q.value("type", ""), "experiment.finished") << q.dump().substr(0, 300);
  EXPECT_EQ(answered, 7);
  client.close();
  EXPECT_EQ(studio.terminate(), 0);
  const auto exported =
      texel::test_support::run_cli(TEXEL_WITH_TEST_KIND, "experiment export --db " + db + " -o " + dir.at("t.csv"));
  ASSERT_EQ(exported.status, 0) << exported.out;
  const std::string text = texel::read_file(dir.at("t.csv"));
  std::size_t rows = 0;
  for (std::size_t at = text.find(",press-side,"); at != std::string::npos; at = text.find(",press-side,", at + 1)) ++rows;
  EXPECT_EQ(rows, 7u);
}
#endif

}  // namespace
