// Real time on N channels (issue #40): `texel play --backend audio` of an
// 8-channel simultaneous document on a JACK server with its dummy driver
// (started and stopped here, its own server name, 8 playback ports), through
// PortAudio's JACK host API: the player's client shows 8 output ports, each
// connected to its playback port, and the run completes. Skipped (not
// faked) where jackd or jack_lsp is missing.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include "../support/cli_run.hpp"
#include "../support/temp_dir.hpp"

namespace {

bool on_path(const char* tool) { return std::system((std::string("command -v ") + tool + " >/dev/null 2>&1").c_str()) == 0; }

std::string pad_8() {
  std::string actuators;
  for (int c = 0; c < 8; ++c)
    actuators +=
        (c ? "," : "") + std::string(R"({"name": "a)") + std::to_string(c) + R"(", "offset_mm": )" + std::to_string(c - 4) + "}";
  return R"({"format": "texel-document", "version": 6, "device": {"name": "pad-8", "samples": 12000, "spacing_mm": 0.01,
      "format": "f32le", "refresh_hz": 48000, "actuators": [)" +
         actuators + R"(]}, "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": 5,
      "texel_length_mm": 0.25, "seed": 40}, "playback": {"mode": "simultaneous"}})";
}

TEST(MultichannelJack, PlaysEightChannelsOnEightJackPorts) {
  if (!on_path("jackd") || !on_path("jack_lsp")) GTEST_SKIP() << "jackd / jack_lsp not installed (Debian jackd2)";
  texel::test_support::TempDir tmp{"texel-mc-jack"};
  const std::string doc = tmp.write("pad8.texel.json", pad_8());
  const std::string server = "texel-mc-test-" + std::to_string(::getpid());
  const pid_t jackd = ::fork();
  ASSERT_GE(jackd, 0);
  if (jackd == 0) {
    const std::string log = tmp.at("jackd.log");
    std::freopen(log.c_str(), "w", stdout);
    std::freopen(log.c_str(), "a", stderr);
    ::execlp("jackd", "jackd", "-n", server.c_str(), "-d", "dummy", "-r", "48000", "-p", "64", "-P", "8",
             static_cast<char*>(nullptr));
    ::_exit(127);
  }
  struct Stop {
    pid_t pid;
    ~Stop() {
      ::kill(pid, SIGTERM);
      ::waitpid(pid, nullptr, 0);
    }
  } stop{jackd};
  const std::string env = "JACK_DEFAULT_SERVER=" + server;
  bool up = false;
  for (int i = 0; i < 50 && !up; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    up = texel::test_support::run_cli("jack_lsp", "", false, env).out.find("system:playback_8") != std::string::npos;
  }
  ASSERT_TRUE(up) << "jackd did not come up";
  // Play 2 s in the background; look at the ports while it plays.
  const std::string out = tmp.at("play.json");
  const std::string play = env + " " + TEXEL_CLI + " play " + doc + " --backend audio --duration 2 --json > " + out + " 2>&1";
  std::thread player([&] { (void)std::system(play.c_str()); });
  std::string ports;
  for (int i = 0; i < 30 && ports.find("out_7") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ports = texel::test_support::run_cli("jack_lsp", "-c", false, env).out;
  }
  player.join();
  for (int c = 0; c < 8; ++c) {
    const std::string port = ":out_" + std::to_string(c) + "\n   system:playback_" + std::to_string(c + 1);
    EXPECT_NE(ports.find(port), std::string::npos) << "port " << c << " not connected:\n" << ports;
  }
  std::ifstream in(out);
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(json.find("8 channels"), std::string::npos) << json;
  EXPECT_NE(json.find("\"interrupted\": false"), std::string::npos) << json;
  EXPECT_EQ(json.find("\"blocks\": 0,"), std::string::npos) << json;
}

}  // namespace
