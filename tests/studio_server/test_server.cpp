// The studio server's transport against a fake message handler (no
// Service): static files and every path-traversal shape, the WebSocket
// round trip, binary and oversized frames, floods, connection limits,
// half-open and reset peers, a reader that never reads, Origin checks and a
// clean stop. Timeouts are shortened through ServerLimits so each test is quick.
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"
#include "client.hpp"
#include "texel/error.hpp"
#include "texel/studio/server.hpp"

namespace {

using namespace std::chrono_literals;
using texel::studio::MessageHandler;
using texel::studio::Server;
using texel::studio::ServerOptions;
using texel::studio::Sink;
using texel::test_support::HttpReply;
using texel::test_support::TempDir;
using texel::test_support::WsClient;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// Echoes text; "big N K" answers K replies of N bytes; "throw" throws.
// Records connects and disconnects to check that they pair exactly once.
class FakeHandler final : public MessageHandler {
 public:
  std::uint64_t connect(Sink sink) override {
    std::lock_guard lock(mutex_);
    const std::uint64_t id = next_++;
    sinks_[id] = sink;
    kept_.push_back(std::move(sink));
    return id;
  }
  void handle(std::uint64_t client, std::string_view text) override {
    Sink sink;
    {
      std::lock_guard lock(mutex_);
      ++messages_;
      sink = sinks_.at(client);
    }
    if (text == "throw") throw std::runtime_error("fake failure");
    if (text.rfind("big ", 0) == 0) {
      std::size_t n = 0, k = 0;
      std::sscanf(std::string(text).c_str(), "big %zu %zu", &n, &k);
      for (std::size_t i = 0; i < k; ++i) sink(std::string(n, 'x'));
      return;
    }
    sink(std::string(text));
  }
  void disconnect(std::uint64_t client) override {
    std::lock_guard lock(mutex_);
    if (!sinks_.count(client) || !gone_.insert(client).second) ++bad_disconnects_;
    changed_.notify_all();
  }

  /// Waits until `n` clients have disconnected; false on timeout.
  bool wait_disconnects(std::size_t n, std::chrono::milliseconds timeout = 5s) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return gone_.size() >= n; });
  }
  std::size_t connects() {
    std::lock_guard lock(mutex_);
    return sinks_.size();
  }
  std::size_t disconnects() {
    std::lock_guard lock(mutex_);
    return gone_.size();
  }
  std::size_t messages() {
    std::lock_guard lock(mutex_);
    return messages_;
  }
  int bad_disconnects() {
    std::lock_guard lock(mutex_);
    return bad_disconnects_;
  }
  /// Every sink ever handed out, kept alive past its connection.
  std::vector<Sink> kept_sinks() {
    std::lock_guard lock(mutex_);
    return kept_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::uint64_t, Sink> sinks_;
  std::vector<Sink> kept_;
  std::set<std::uint64_t> gone_;
  std::uint64_t next_ = 1;
  std::size_t messages_ = 0;
  int bad_disconnects_ = 0;
};

// web/ holds a small front end; secret.txt sits beside it, outside the root.
struct Site {
  TempDir dir{"texel-studio-server"};
  fs::path web = dir.path / "web";
  Site() {
    fs::create_directories(web / "assets");
    write("index.html", "<!doctype html><title>studio</title>");
    write("app.js", "console.log('studio')");
    write("assets/style.css", "body{}");
    write("assets/icon.svg", "<svg/>");
    write("assets/data.json", "{}");
    write("assets/mod.wasm", "\0asm");
    write("assets/font.woff2", "wOF2");
    write("assets/blob.xyz", "?");
    dir.write("secret.txt", "TOP SECRET");
  }
  void write(const std::string& name, const std::string& text) const { std::ofstream(web / name) << text; }
};

// A server on 127.0.0.1, port 0, running on its own thread until the test ends.
struct Running {
  FakeHandler& handler;
  Server server;
  std::uint16_t port = 0;
  std::thread thread;

  Running(FakeHandler& h, ServerOptions options) : handler(h), server(h, std::move(options)) {
    port = server.start();
    thread = std::thread([this] { server.run(); });
  }
  ~Running() {
    server.stop();
    thread.join();
  }
};

ServerOptions options_for(const Site& site) {
  ServerOptions o;
  o.web_root = site.web.string();
  return o;
}

long rss_kib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

// Waits until `pred` holds; false after `timeout`.
template <class Pred>
bool eventually(Pred pred, std::chrono::milliseconds timeout = 5s) {
  const auto deadline = Clock::now() + timeout;
  while (!pred()) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(5ms);
  }
  return true;
}

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// Every test has a site, a fake handler and, once start() is called, a
// server running on its own thread; they go in reverse order at the end of
// the test (the server stops first).
class ServerTest : public ::testing::Test {
 protected:
  Site site;
  FakeHandler h;
  std::optional<Running> running;

  ServerOptions options() const { return options_for(site); }
  Running& start(ServerOptions o) { return running.emplace(h, std::move(o)); }
  Running& start() { return start(options()); }
};
class StudioServerHttp : public ServerTest {};
class StudioServerStart : public ServerTest {};
class StudioServerWs : public ServerTest {};

// ------------------------------------------------------------------ HTTP

TEST_F(StudioServerHttp, ServesFilesWithTheirMimeTypes) {
  Running& r = start();
  const std::pair<std::string, std::string> cases[] = {
      {"/", "text/html; charset=utf-8"},
      {"/index.html", "text/html; charset=utf-8"},
      {"/app.js?v=3", "text/javascript; charset=utf-8"},
      {"/assets/style.css", "text/css; charset=utf-8"},
      {"/assets/icon.svg", "image/svg+xml"},
      {"/assets/data.json", "application/json"},
      {"/assets/mod.wasm", "application/wasm"},
      {"/assets/font.woff2", "font/woff2"},
      {"/assets/blob.xyz", "application/octet-stream"},
  };
  for (const auto& [target, mime] : cases) {
    const HttpReply reply = texel::test_support::http_request(r.port, "GET", target);
    EXPECT_EQ(reply.status, 200) << target;
    EXPECT_EQ(reply.header("content-type"), mime) << target;
    EXPECT_EQ(reply.header("x-content-type-options"), "nosniff") << target;
  }
  const HttpReply index = texel::test_support::http_request(r.port, "GET", "/");
  EXPECT_EQ(index.body, "<!doctype html><title>studio</title>");
  EXPECT_EQ(index.header("cache-control"), "no-cache");
  EXPECT_EQ(texel::test_support::http_request(r.port, "GET", "/app.js").header("cache-control"), "");
}

TEST_F(StudioServerHttp, HeadSendsTheLengthWithoutABody) {
  Running& r = start();
  const HttpReply reply = texel::test_support::http_request(r.port, "HEAD", "/app.js");
  EXPECT_EQ(reply.status, 200);
  EXPECT_EQ(reply.header("content-length"), "21");
  EXPECT_EQ(reply.body, "");
  const HttpReply missing = texel::test_support::http_request(r.port, "HEAD", "/nope.js");
  EXPECT_EQ(missing.status, 404);
  EXPECT_EQ(missing.body, "");
}

TEST_F(StudioServerHttp, OnlyGetAndHeadAreAllowed) {
  Running& r = start();
  for (const std::string method : {"POST", "PUT", "DELETE", "OPTIONS", "PATCH"}) {
    const HttpReply reply = texel::test_support::http_raw(
        r.port, method + " /index.html HTTP/1.1\r\nHost: x\r\nContent-Length: 2\r\nConnection: close\r\n\r\nhi");
    EXPECT_EQ(reply.status, 405) << method;
    EXPECT_EQ(reply.header("allow"), "GET, HEAD") << method;
  }
}

TEST_F(StudioServerHttp, MissingFilesAndDirectoriesAreNotFound) {
  Running& r = start();
  for (const std::string target : {"/missing.js", "/assets", "/assets/", "/assets/missing/", "/ws", "/.hidden"}) {
    const HttpReply reply = texel::test_support::http_request(r.port, "GET", target);
    EXPECT_EQ(reply.status, 404) << target;
    EXPECT_EQ(reply.body.find("style.css"), std::string::npos) << target << ": no listing";
  }
}

TEST_F(StudioServerHttp, PathTraversalIsRefused) {
  Running& r = start();
  const std::string targets[] = {
      "/../secret.txt",
      "/%2e%2e/secret.txt",
      "/%2E%2E/secret.txt",
      "/%2e%2e%2fsecret.txt",
      "/assets/../../secret.txt",
      "/assets/%2e%2e/%2e%2e/secret.txt",
      "//etc/passwd",
      "/..%5csecret.txt",
      "/assets\\..\\..\\secret.txt",
      "/index.html%00.js",
      "/%00",
      "/bad%zzescape",
      "/trailing%2",
      "/./index.html",
      "http://127.0.0.1/../secret.txt",
      "http://127.0.0.1/index.html",
      "*",
      (site.dir.path / "secret.txt").string(),
  };
  for (const auto& target : targets) {
    const HttpReply reply = texel::test_support::http_request(r.port, "GET", target);
    EXPECT_TRUE(reply.status == 400 || reply.status == 404) << target << " → " << reply.status;
    EXPECT_EQ(reply.body.find("SECRET"), std::string::npos) << target;
  }
  // Raw bytes the client helper would otherwise never send.
  static constexpr char nul_request[] = "GET /index.html\0x HTTP/1.1\r\nHost: x\r\n\r\n";
  const HttpReply nul = texel::test_support::http_raw(r.port, std::string(nul_request, sizeof nul_request - 1));
  EXPECT_EQ(nul.status, 400);
  // The server is still there.
  EXPECT_EQ(texel::test_support::http_request(r.port, "GET", "/").status, 200);
}

TEST_F(StudioServerHttp, SymlinksLeadingOutAreRefusedAndInsideAreServed) {
  fs::create_symlink(site.dir.path / "secret.txt", site.web / "leak.txt");
  fs::create_directory_symlink("/etc", site.web / "etc");
  fs::create_directory_symlink(site.dir.path, site.web / "assets" / "up");
  fs::create_symlink(site.web / "app.js", site.web / "alias.js");
  fs::create_symlink("../app.js", site.web / "assets" / "relative.js");
  Running& r = start();
  for (const std::string target : {"/leak.txt", "/etc/passwd", "/etc/hostname", "/assets/up/secret.txt"}) {
    const HttpReply reply = texel::test_support::http_request(r.port, "GET", target);
    EXPECT_EQ(reply.status, 404) << target;
    EXPECT_EQ(reply.body.find("SECRET"), std::string::npos) << target;
  }
  EXPECT_EQ(texel::test_support::http_request(r.port, "GET", "/alias.js").body, "console.log('studio')");
  EXPECT_EQ(texel::test_support::http_request(r.port, "GET", "/assets/relative.js").status, 200);
}

TEST_F(StudioServerHttp, OversizedHeadersAndBodiesAreRefused) {
  ServerOptions o = options();
  o.limits.max_request_bytes = 4096;
  Running& r = start(o);
  const HttpReply big_header =
      texel::test_support::http_raw(r.port, "GET / HTTP/1.1\r\nHost: x\r\nX-Junk: " + std::string(8000, 'a') + "\r\n\r\n");
  EXPECT_EQ(big_header.status, 431);
  const HttpReply big_body = texel::test_support::http_raw(
      r.port, "GET / HTTP/1.1\r\nHost: x\r\nContent-Length: 100000\r\n\r\n" + std::string(100000, 'b'));
  EXPECT_EQ(big_body.status, 413);
  const HttpReply garbage = texel::test_support::http_raw(r.port, "NOT HTTP AT ALL\r\n\r\n");
  EXPECT_EQ(garbage.status, 400);
  EXPECT_EQ(texel::test_support::http_request(r.port, "GET", "/").status, 200);
}

TEST_F(StudioServerHttp, KeepAliveServesSeveralRequestsOnOneConnection) {
  Running& r = start();
  const HttpReply reply = texel::test_support::http_raw(
      r.port, "GET /app.js HTTP/1.1\r\nHost: x\r\n\r\nGET /index.html HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  EXPECT_EQ(reply.status, 200);
  EXPECT_NE(reply.body.find("<title>studio</title>"), std::string::npos) << "second response arrived";
}

TEST_F(StudioServerHttp, SlowlorisHeaderIsReapedByTheRequestTimeout) {
  ServerOptions o = options();
  o.limits.http_timeout = 300ms;
  Running& r = start(o);
  const int fd = texel::test_support::tcp_connect(r.port);
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(texel::test_support::send_all(fd, "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: "));
  const auto t0 = Clock::now();
  const std::string rest = texel::test_support::read_until_close(fd, 5s);
  const double reaped_ms = ms_since(t0);
  ::close(fd);
  EXPECT_EQ(rest, "") << "closed without an answer";
  EXPECT_GT(reaped_ms, 200);
  EXPECT_LT(reaped_ms, 2000);
  EXPECT_TRUE(eventually([&] { return r.server.connections() == 0; }));
  std::printf("half-open HTTP connection reaped after %.0f ms (timeout 300 ms)\n", reaped_ms);
}

// ------------------------------------------------------------- start-up checks

TEST_F(StudioServerStart, AMissingFrontEndIsAClearError) {
  ServerOptions o;
  o.web_root = "/nonexistent/web";
  Server server(h, o);
  try {
    server.start();
    FAIL() << "started without a front end";
  } catch (const texel::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/web"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("make demo"), std::string::npos) << e.what();
  }
}

TEST_F(StudioServerStart, NonLoopbackAddressesNeedAllowRemote) {
  ServerOptions o;
  o.address = "0.0.0.0";
  EXPECT_THROW(Server(h, o), texel::InvalidArgument);
  o.address = "not-an-ip";
  EXPECT_THROW(Server(h, o), texel::InvalidArgument);
  o.address = "0.0.0.0";
  o.allow_remote = true;
  EXPECT_NO_THROW(Server(h, o));
  EXPECT_TRUE(texel::studio::is_loopback_address("127.0.0.1"));
  EXPECT_TRUE(texel::studio::is_loopback_address("127.1.2.3"));
  EXPECT_TRUE(texel::studio::is_loopback_address("::1"));
  EXPECT_TRUE(texel::studio::is_loopback_address("::ffff:127.0.0.1"));
  EXPECT_FALSE(texel::studio::is_loopback_address("0.0.0.0"));
  EXPECT_FALSE(texel::studio::is_loopback_address("192.168.1.2"));
  EXPECT_FALSE(texel::studio::is_loopback_address("localhost"));
}

TEST_F(StudioServerStart, APortInUseIsAClearError) {
  Running& first = start();
  ServerOptions o = options();
  o.port = first.port;
  Server second(h, o);
  try {
    second.start();
    FAIL() << "two servers on one port";
  } catch (const texel::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot listen on 127.0.0.1:" + std::to_string(first.port)), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(first.server.url(), "http://127.0.0.1:" + std::to_string(first.port) + "/");
}

// ----------------------------------------------------------------- WebSocket

TEST_F(StudioServerWs, TextRoundTripAndOneDisconnectPerConnect) {
  Running& r = start();
  {
    WsClient c;
    ASSERT_TRUE(c.connect(r.port)) << c.error();
    EXPECT_EQ(c.status(), 101);
    for (int i = 0; i < 3; ++i) {
      const std::string msg = R"({"type":"hello","id":)" + std::to_string(i) + "}";
      ASSERT_TRUE(c.send_text(msg));
      EXPECT_EQ(c.read(), msg);
    }
    c.close();
  }
  ASSERT_TRUE(h.wait_disconnects(1));
  EXPECT_EQ(h.connects(), 1u);
  EXPECT_EQ(h.bad_disconnects(), 0);
  EXPECT_TRUE(eventually([&] { return r.server.connections() == 0; }));
}

TEST_F(StudioServerWs, UpgradesElsewhereThanWsAreNotFound) {
  Running& r = start();
  for (const std::string target : {"/", "/index.html", "/ws/x", "/wss"}) {
    WsClient c;
    EXPECT_FALSE(c.connect(r.port, target)) << target;
    EXPECT_EQ(c.status(), 404) << target;
  }
  WsClient query;
  EXPECT_TRUE(query.connect(r.port, "/ws?session=1")) << query.error();
  EXPECT_TRUE(eventually([&] { return h.connects() == 1; }));
}

TEST_F(StudioServerWs, BrowserOriginsMustBeThisServer) {
  ServerOptions o = options();
  o.allowed_origins = {"http://localhost:5173"};
  Running& r = start(o);
  const std::string port = std::to_string(r.port);
  struct Case {
    std::string origin, host;
    int status;
  };
  const Case cases[] = {
      {"", "", 101},                                                 // not a browser
      {"http://127.0.0.1:" + port, "", 101},                         // our own page
      {"http://localhost:" + port, "localhost:" + port, 101},        // addressed by name
      {"http://[::1]:" + port, "[::1]:" + port, 101},                // IPv6 literal
      {"http://localhost:5173", "", 101},                            // listed (a dev server)
      {"http://evil.example", "", 403},                              // another site
      {"http://127.0.0.1:1", "", 403},                               // another local server
      {"null", "", 403},                                             // file:// or sandboxed
      {"http://evil.example:" + port, "evil.example:" + port, 403},  // DNS rebinding
      {"https://127.0.0.1:" + port, "", 403},                        // wrong scheme
  };
  for (const auto& c : cases) {
    WsClient client;
    client.connect(r.port, "/ws", c.origin, c.host);
    EXPECT_EQ(client.status(), c.status) << "origin " << c.origin << " host " << c.host;
  }
}

TEST_F(StudioServerWs, BinaryFramesGetAnErrorAndNeverReachTheHandler) {
  Running& r = start();
  WsClient c;
  ASSERT_TRUE(c.connect(r.port));
  ASSERT_TRUE(c.send_binary(std::string("\x00\x01\x02", 3)));
  EXPECT_EQ(c.read(), R"({"type":"error","code":"bad_message","message":"binary frames are not accepted"})");
  EXPECT_EQ(h.messages(), 0u);
  ASSERT_TRUE(c.send_text("still here"));
  EXPECT_EQ(c.read(), "still here");
}

TEST_F(StudioServerWs, AThrowingHandlerIsAnsweredAndTheConnectionStays) {
  Running& r = start();
  WsClient c;
  ASSERT_TRUE(c.connect(r.port));
  ASSERT_TRUE(c.send_text("throw"));
  EXPECT_EQ(c.read(), R"({"type":"error","code":"internal","message":"the message handler failed"})");
  ASSERT_TRUE(c.send_text("after"));
  EXPECT_EQ(c.read(), "after");
}

TEST_F(StudioServerWs, OversizedMessagesCloseWithTooBig) {
  ServerOptions o = options();
  o.limits.max_message_bytes = 1024;
  Running& r = start(o);
  WsClient c;
  ASSERT_TRUE(c.connect(r.port));
  ASSERT_TRUE(c.send_text(std::string(1024, 'a')));
  EXPECT_EQ(c.read()->size(), 1024u);
  c.send_text(std::string(1025, 'a'));
  EXPECT_EQ(c.read(), std::nullopt);
  EXPECT_EQ(c.close_code(), 1009);
  ASSERT_TRUE(h.wait_disconnects(1));
  EXPECT_EQ(h.messages(), 1u);
  WsClient next;
  ASSERT_TRUE(next.connect(r.port));
  ASSERT_TRUE(next.send_text("ok"));
  EXPECT_EQ(next.read(), "ok");
}

TEST_F(StudioServerWs, InvalidUtf8TextIsRefused) {
  Running& r = start();
  WsClient c;
  ASSERT_TRUE(c.connect(r.port));
  c.send_raw(texel::test_support::ws_frame_header(2) + "\xc3\x28");
  EXPECT_EQ(c.read(), std::nullopt);
  EXPECT_EQ(c.close_code(), 1007);
  ASSERT_TRUE(h.wait_disconnects(1));
  EXPECT_EQ(h.messages(), 0u);
}

TEST_F(StudioServerWs, AFloodOfTenThousandMessagesIsAnsweredInOrder) {
  Running& r = start();
  WsClient flooder;
  ASSERT_TRUE(flooder.connect(r.port));
  constexpr int n = 10000;
  const auto t0 = Clock::now();
  std::thread writer([&] {
    for (int i = 0; i < n; ++i)
      flooder.send_raw(texel::test_support::ws_frame_header(std::to_string(i).size()) + std::to_string(i));
  });
  // Another client is served meanwhile.
  WsClient other;
  ASSERT_TRUE(other.connect(r.port));
  ASSERT_TRUE(other.send_text("other"));
  EXPECT_EQ(other.read(), "other");
  writer.join();
  int in_order = 0;
  for (int i = 0; i < n; ++i)
    if (flooder.read() == std::to_string(i)) ++in_order;
  const double ms = ms_since(t0);
  EXPECT_EQ(in_order, n);
  std::printf("flood: %d messages echoed in %.0f ms (%.0f messages/s)\n", n, ms, n / ms * 1000);
}

TEST_F(StudioServerWs, ConnectionsBeyondTheLimitAreRefusedWith503) {
  ServerOptions o = options();
  o.limits.max_connections = 4;
  Running& r = start(o);
  std::vector<std::unique_ptr<WsClient>> clients;
  for (int i = 0; i < 4; ++i) {
    clients.push_back(std::make_unique<WsClient>());
    ASSERT_TRUE(clients.back()->connect(r.port)) << i << ": " << clients.back()->status() << " " << clients.back()->error();
  }
  WsClient extra;
  EXPECT_FALSE(extra.connect(r.port));
  EXPECT_EQ(extra.status(), 503);
  EXPECT_EQ(texel::test_support::http_request(r.port, "GET", "/").status, 503);
  for (auto& c : clients) {
    ASSERT_TRUE(c->send_text("alive"));
    EXPECT_EQ(c->read(), "alive");
  }
  clients[0]->close();
  ASSERT_TRUE(h.wait_disconnects(1));
  EXPECT_TRUE(eventually([&] { return r.server.connections() == 3; }));
  WsClient again;
  EXPECT_TRUE(again.connect(r.port)) << again.error();
}

TEST_F(StudioServerWs, AStalledPartialFrameIsReapedByTheIdleTimeout) {
  ServerOptions o = options();
  o.limits.ws_idle_timeout = 400ms;
  Running& r = start(o);
  WsClient c;
  ASSERT_TRUE(c.connect(r.port));
  ASSERT_TRUE(c.send_raw(texel::test_support::ws_frame_header(1000) + std::string(10, 'a')));
  const auto t0 = Clock::now();
  ASSERT_TRUE(h.wait_disconnects(1, 3s));
  const double reaped_ms = ms_since(t0);
  EXPECT_LT(reaped_ms, 1500);
  EXPECT_EQ(h.messages(), 0u);
  EXPECT_TRUE(eventually([&] { return r.server.connections() == 0; }));
  std::printf("half-open WebSocket (stalled mid-frame) reaped after %.0f ms (idle timeout 400 ms)\n", reaped_ms);
}

TEST_F(StudioServerWs, AStalledHandshakeIsReaped) {
  ServerOptions o = options();
  o.limits.http_timeout = 300ms;
  Running& r = start(o);
  const int fd = texel::test_support::tcp_connect(r.port);
  ASSERT_TRUE(texel::test_support::send_all(fd, "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n"));
  EXPECT_EQ(texel::test_support::read_until_close(fd, 3s), "");
  ::close(fd);
  EXPECT_EQ(h.connects(), 0u);
}

TEST_F(StudioServerWs, AnAbruptResetMidFrameDisconnectsOnce) {
  Running& r = start();
  for (int i = 0; i < 20; ++i) {
    WsClient c;
    ASSERT_TRUE(c.connect(r.port));
    c.send_raw(texel::test_support::ws_frame_header(100000) + std::string(5000, 'a'));
    c.reset();
  }
  ASSERT_TRUE(h.wait_disconnects(20));
  EXPECT_EQ(h.connects(), 20u);
  EXPECT_EQ(h.bad_disconnects(), 0);
  EXPECT_EQ(h.messages(), 0u);
  EXPECT_TRUE(eventually([&] { return r.server.connections() == 0; }));
}

TEST_F(StudioServerWs, AReaderThatNeverReadsIsDroppedAndMemoryStaysBounded) {
  ServerOptions o = options();
  o.limits.max_queued_bytes = 1u << 20;
  Running& r = start(o);
  const long before = rss_kib();
  WsClient slow;
  ASSERT_TRUE(slow.connect(r.port));
  // 4000 replies of 64 KiB (250 MiB) asked for, none read.
  ASSERT_TRUE(slow.send_text("big 65536 4000"));
  ASSERT_TRUE(h.wait_disconnects(1));
  const long after = rss_kib();
#if !defined(__SANITIZE_ADDRESS__)  // AddressSanitizer's quarantine keeps the freed replies resident
  EXPECT_LT(after - before, 64 * 1024) << "RSS grew by " << (after - before) << " KiB";
#endif
  std::printf("slow reader dropped; server RSS %ld KiB before, %ld KiB after (+%ld KiB for 250 MiB of replies asked)\n", before,
              after, after - before);
  WsClient other;
  ASSERT_TRUE(other.connect(r.port));
  ASSERT_TRUE(other.send_text("fine"));
  EXPECT_EQ(other.read(), "fine");
}

TEST_F(StudioServerWs, LateSinkCallsAfterCloseAreHarmless) {
  {
    Running& r = start();
    WsClient c;
    ASSERT_TRUE(c.connect(r.port));
    c.close();
    ASSERT_TRUE(h.wait_disconnects(1));
    for (auto& sink : h.kept_sinks()) sink("late reply, connection closed");
  }
  running.reset();  // the server is gone
  for (auto& sink : h.kept_sinks()) sink("late reply, server gone");
  SUCCEED();
}

TEST_F(StudioServerWs, StopSaysGoingAwayAndRunReturns) {
  Server server(h, options());
  const std::uint16_t port = server.start();
  std::thread runner([&] { server.run(); });
  WsClient a, b;
  ASSERT_TRUE(a.connect(port));
  ASSERT_TRUE(b.connect(port));
  ASSERT_TRUE(eventually([&] { return h.connects() == 2; }));  // the client may see 101 first
  const int idle = texel::test_support::tcp_connect(port);     // an HTTP connection that never asks
  const auto t0 = Clock::now();
  server.stop();
  for (WsClient* c : {&a, &b}) {
    EXPECT_EQ(c->read(), std::nullopt);  // reading answers the closing handshake
    EXPECT_EQ(c->close_code(), 1001);
  }
  runner.join();
  const double stop_ms = ms_since(t0);
  ::close(idle);
  EXPECT_EQ(h.disconnects(), 2u);
  EXPECT_EQ(h.bad_disconnects(), 0);
  EXPECT_LT(stop_ms, 3000);
  std::printf("stop with 3 open connections: run() returned after %.0f ms\n", stop_ms);
}

TEST_F(StudioServerWs, StopCutsAPeerThatIgnoresTheClosingHandshake) {
  ServerOptions o = options();
  o.limits.stop_grace = 300ms;
  Server server(h, o);
  const std::uint16_t port = server.start();
  std::thread runner([&] { server.run(); });
  WsClient deaf;  // never reads, so never answers the close frame
  ASSERT_TRUE(deaf.connect(port));
  ASSERT_TRUE(eventually([&] { return h.connects() == 1; }));
  const auto t0 = Clock::now();
  server.stop();
  runner.join();
  EXPECT_LT(ms_since(t0), 2000);
  EXPECT_EQ(h.disconnects(), 1u);
}

}  // namespace
