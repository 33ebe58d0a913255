// texel studio — Texel Studio in the browser (docs/studio.md): the Service
// (designer, "Feel it", experiments) behind the HTTP + WebSocket server.
// The command only wires them: it parses, opens the Service and the server,
// prints the address and serves until Ctrl-C / SIGTERM.
//
// Defaults that depend on where texel runs from:
// - the front end: <directory of this executable>/../web, which is where
//   the build puts it (build/bin/texel serves build/web, built by `make demo`);
// - the shipped protocols: the source tree's examples/protocols, compiled in
//   as TEXEL_STUDIO_PROTOCOLS_DIR, when that directory exists (none otherwise).
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "texel/player.hpp"
#include "texel/studio/server.hpp"
#include "texel/studio/service.hpp"

extern char** environ;

namespace texel::cli {
namespace {

namespace fs = std::filesystem;

struct StudioArgs {
  int port = 8080;
  std::string address = "127.0.0.1";
  bool allow_remote = false;
  std::vector<std::string> allow_origins;
  std::string db = "texel-studio.db";
  std::string backend = "null";
  std::string audio_device;
  std::string response = "limit";
  std::size_t channels = 1;
  std::string web;
  std::string protocols;
  bool open = false;
};

std::string default_web_root() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("web") : (exe.parent_path().parent_path() / "web").string();
}

std::string default_protocols_dir() {
  std::error_code ec;
  return fs::is_directory(TEXEL_STUDIO_PROTOCOLS_DIR, ec) ? std::string(TEXEL_STUDIO_PROTOCOLS_DIR) : std::string();
}

// Opens the page in the desktop's browser when xdg-open exists; never fatal.
void open_browser(const std::string& url) {
  const char* argv[] = {"xdg-open", url.c_str(), nullptr};
  pid_t pid = 0;
  if (::posix_spawnp(&pid, "xdg-open", nullptr, nullptr, const_cast<char**>(argv), environ) != 0) {
    std::cerr << "texel: --open: xdg-open is not available; open " << url << " yourself\n";
    return;
  }
  std::thread([pid] { ::waitpid(pid, nullptr, 0); }).detach();
}

void run(const StudioArgs& a) {
  studio::ServiceOptions so;
  so.db_path = a.db;
  so.backend = a.backend;
  so.audio_device = a.audio_device;
  so.response = a.response;
  so.channels = a.channels;
  (void)parse_response_handling(a.response, "--response");  // named as the flag (the service says "response")
  so.protocols_dir = a.protocols.empty() ? default_protocols_dir() : a.protocols;
  studio::Service service(so);  // declared first: the server, destroyed before it, drops its clients first

  studio::ServerOptions o;
  o.address = a.address;
  o.port = static_cast<std::uint16_t>(a.port);
  o.web_root = a.web.empty() ? default_web_root() : a.web;
  o.allow_remote = a.allow_remote;
  o.allowed_origins = a.allow_origins;
  o.stop_on_signals = true;
  studio::Server server(service, o);
  server.start();
  if (!studio::is_loopback_address(a.address))
    std::cerr << "texel: warning: serving on " << a.address
              << ", reachable from other machines; the studio has no authentication\n";
  std::cout << "Texel Studio at " << server.url() << std::endl;
  std::cout << "  backend " << service.describe() << "; store " << a.db << "; Ctrl-C stops" << std::endl;
  if (a.open) open_browser(server.url());
  server.run();
  std::cout << "Texel Studio stopped" << std::endl;
}

}  // namespace

void register_studio(CLI::App& app) {
  auto args = std::make_shared<StudioArgs>();
  auto* cmd = app.add_subcommand("studio", "serve Texel Studio (designer, Feel it, experiments) to a browser");
  cmd->add_option("--port", args->port, "TCP port; 0 picks a free one")->check(CLI::Range(0, 65535))->capture_default_str();
  cmd->add_option("--address", args->address, "IP address to bind; other than loopback needs --allow-remote")
      ->capture_default_str();
  cmd->add_flag("--allow-remote", args->allow_remote, "permit a non-loopback --address (no authentication!)");
  cmd->add_option("--allow-origin", args->allow_origins,
                  "another browser origin allowed to open the WebSocket, e.g. a dev server http://localhost:5173");
  cmd->add_option("--db", args->db,
                  "experiment store (SQLite; created on first use), or a PostgreSQL server (postgresql://… or service=NAME): "
                  "the studio is then a station with its journal at the default place (docs/session-store.md)")
      ->capture_default_str();
  cmd->add_option("--backend", args->backend, "null, audio or serial:PATH")->capture_default_str();
  cmd->add_option("--audio-device", args->audio_device, "PortAudio output device for --backend audio (index or name)");
  cmd->add_option("--response", args->response,
                  "The shown document's display frequency response (device profile): limit (never drive what the "
                  "display attenuates by 20 dB or more) or off")
      ->capture_default_str();
  cmd->add_option("--channels", args->channels,
                  "output channels to open with, 1 … 64; a study or document on an actuator array re-opens the output with its "
                  "device's actuators")
      ->capture_default_str();
  cmd->add_option("--web", args->web, "the built front end (default: <texel dir>/../web, built by make demo)");
  cmd->add_option("--protocols", args->protocols,
                  "directory of shipped protocols (default: the source tree's examples/protocols)");
  cmd->add_flag("--open", args->open, "open the page with xdg-open");
  cmd->callback([args] { run(*args); });
}

}  // namespace texel::cli
