// The studio's HTTP + WebSocket transport on Boost.Beast (design and limits
// in server.hpp, protocol in docs/studio.md). All Beast code of the library
// lives in this one translation unit: it compiles slowly.
#include "texel/studio/server.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <csignal>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <utility>

#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "texel/error.hpp"

namespace texel::studio {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
namespace fs = std::filesystem;

constexpr const char* server_name = "texel-studio";

// Beast 1.74 speaks boost::string_view.
std::string_view view(beast::string_view s) { return {s.data(), s.size()}; }

std::string lower(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// --------------------------------------------------------------- static files

const char* mime_type(const fs::path& file) {
  static const std::pair<std::string_view, const char*> types[] = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".json", "application/json"},
      {".wasm", "application/wasm"},
      {".ico", "image/x-icon"},
      {".map", "application/json"},
      {".txt", "text/plain; charset=utf-8"},
      {".woff2", "font/woff2"},
  };
  const std::string ext = lower(file.extension().string());
  for (const auto& [e, type] : types)
    if (ext == e) return type;
  return "application/octet-stream";
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

struct Lookup {
  http::status status = http::status::ok;
  fs::path file;
};

// Maps a request target to a file under `root` (canonical). Decodes first,
// then checks, so "%2e%2e%2f" is judged as the "../" it means; the final
// containment check on the resolved path is what actually keeps requests
// inside the root (symlinks included); the earlier refusals give clearer
// answers and never let a suspicious path reach the file system at all.
Lookup lookup(const fs::path& root, std::string_view target) {
  // Only origin-form targets: absolute URLs ("http://x/..."), authority
  // and asterisk forms have no business with a static file server.
  if (target.empty() || target.front() != '/') return {http::status::bad_request, {}};
  target = target.substr(0, target.find_first_of("?#"));
  std::string path;
  path.reserve(target.size());
  for (std::size_t i = 0; i < target.size(); ++i) {
    if (target[i] != '%') {
      path += target[i];
      continue;
    }
    const int hi = i + 2 < target.size() ? hex_value(target[i + 1]) : -1;
    const int lo = hi >= 0 ? hex_value(target[i + 2]) : -1;
    if (lo < 0) return {http::status::bad_request, {}};
    path += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  if (path.find('\0') != std::string::npos || path.find('\\') != std::string::npos) return {http::status::bad_request, {}};

  fs::path relative;
  if (path == "/") {
    relative = "index.html";
  } else {
    std::size_t begin = 1;
    while (begin <= path.size()) {
      const std::size_t end = std::min(path.find('/', begin), path.size());
      const std::string_view segment = std::string_view(path).substr(begin, end - begin);
      const bool last = end == path.size();
      if (segment.empty() && !last) return {http::status::bad_request, {}};  // "//etc/passwd", "/a//b"
      if (segment == "." || segment == "..") return {http::status::bad_request, {}};
      if (!segment.empty() && segment.front() == '.') return {http::status::not_found, {}};  // no .git, .env, …
      relative /= std::string(segment);
      begin = end + 1;
    }
  }
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(root / relative, ec);
  if (ec) return {http::status::not_found, {}};
  if (std::mismatch(root.begin(), root.end(), resolved.begin(), resolved.end()).first != root.end())
    return {http::status::not_found, {}};
  if (!fs::is_regular_file(resolved, ec)) return {http::status::not_found, {}};  // directories: no listing
  return {http::status::ok, resolved};
}

// ------------------------------------------------------------------- origins

// A browser's WebSocket is accepted from the page this server served: its
// Origin is "http://" + the Host it addressed, and that host is an IP
// literal or "localhost" — a name no attacker's DNS can rebind to us.
bool origin_allowed(const http::request<http::string_body>& req, const std::vector<std::string>& allowed) {
  const auto it = req.find(http::field::origin);
  if (it == req.end()) return true;  // not a browser
  const std::string origin = lower(view(it->value()));
  for (const auto& a : allowed)
    if (lower(a) == origin) return true;
  const std::string host = lower(view(req[http::field::host]));
  if (host.empty() || origin != "http://" + host) return false;
  std::string name;
  if (host.front() == '[') {
    const auto close = host.find(']');
    if (close == std::string::npos) return false;
    name = host.substr(1, close - 1);
  } else {
    name = host.substr(0, host.find(':'));
  }
  if (name == "localhost") return true;
  boost::system::error_code ec;
  net::ip::make_address(name, ec);
  return !ec;
}

std::string error_json(std::string_view message) {
  return std::string(R"({"type":"error","code":"bad_message","message":")") + std::string(message) + "\"}";
}

}  // namespace

// ------------------------------------------------------------------ the server

namespace {
class Connection;
}

// Sinks hold this, not the server: once the server is gone (open == false),
// a late reply from a handler thread is dropped instead of being posted to
// a destroyed io_context.
struct Gate {
  std::shared_mutex mutex;
  bool open = true;
};

struct Server::Impl {
  Impl(MessageHandler& h, ServerOptions o) : handler(h), options(std::move(o)), ioc(options.threads) {}

  MessageHandler& handler;
  const ServerOptions options;
  fs::path root;  // canonical web root
  std::shared_ptr<Gate> gate = std::make_shared<Gate>();
  std::atomic<bool> stopping{false};
  std::atomic<bool> torn_down{false};  // ~Server: the io_context is going away
  bool started = false;
  tcp::endpoint endpoint;

  mutable std::mutex registry_mutex;
  std::unordered_map<std::uint64_t, std::weak_ptr<Connection>> registry;
  std::uint64_t next_id = 1;

  // Declared after everything the connections use: destroying the
  // io_context destroys the handlers it still holds, and with them any
  // connection not yet closed, which unregisters and says disconnect().
  net::io_context ioc;
  net::strand<net::io_context::executor_type> strand{net::make_strand(ioc)};  // acceptor, timers, signals
  tcp::acceptor acceptor{strand};
  net::signal_set signals{strand};
  net::steady_timer grace{strand};         // cuts connections that outlive a stop
  net::steady_timer accept_pause{strand};  // after an accept error (e.g. out of descriptors)

  std::uint64_t add(const std::shared_ptr<Connection>& c) {
    std::lock_guard lock(registry_mutex);
    registry.emplace(next_id, c);
    return next_id++;
  }
  void remove(std::uint64_t id) {
    std::lock_guard lock(registry_mutex);
    registry.erase(id);
    if (registry.empty() && stopping && !torn_down) net::post(strand, [this] { grace.cancel(); });
  }
  std::vector<std::shared_ptr<Connection>> live() const {
    std::vector<std::shared_ptr<Connection>> out;
    std::lock_guard lock(registry_mutex);
    for (const auto& [id, w] : registry)
      if (auto c = w.lock()) out.push_back(std::move(c));
    return out;
  }
  std::size_t count() const {
    std::lock_guard lock(registry_mutex);
    return registry.size();
  }

  void accept();
  void on_accept(beast::error_code ec, tcp::socket socket);
  void begin_stop();
};

namespace {

class Connection {
 public:
  virtual ~Connection() = default;
  /// Graceful close (a WebSocket says "going away"); any thread.
  virtual void shutdown() = 0;
  /// Cuts the TCP connection; any thread.
  virtual void abort() = 0;
};

// Beyond max_connections: a fixed 503, written without blocking into the
// fresh socket's empty send buffer. What the client already sent is read
// away first, so closing does not turn into a reset that eats the answer.
void refuse(tcp::socket socket) {
  static constexpr std::string_view busy =
      "HTTP/1.1 503 Service Unavailable\r\nServer: texel-studio\r\nContent-Type: text/plain\r\n"
      "Content-Length: 34\r\nRetry-After: 1\r\nConnection: close\r\n\r\ntoo many connections; retry later\n";
  beast::error_code ec;
  socket.non_blocking(true, ec);
  char scratch[4096];
  while (!ec) socket.read_some(net::buffer(scratch), ec);
  socket.write_some(net::buffer(busy.data(), busy.size()), ec);
  socket.shutdown(tcp::socket::shutdown_send, ec);
  socket.close(ec);
}

// ------------------------------------------------------------------ WebSocket

class WsSession final : public Connection, public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(Server::Impl& server, tcp::socket&& socket)
      : server_(server), executor_(socket.get_executor()), ws_(std::move(socket)) {}

  ~WsSession() override {
    // Only when the io_context was torn down with this session still open.
    if (client_ && !finished_) server_.handler.disconnect(*client_);
    if (id_) server_.remove(id_);
  }

  void run(http::request<http::string_body> req) {
    id_ = server_.add(shared_from_this());
    // Upgraded while the server stops: stop()'s round of shutdowns may have
    // missed this session, so it closes itself once the handshake is done.
    closing_ = server_.stopping;
    const auto& limits = server_.options.limits;
    beast::get_lowest_layer(ws_).expires_never();  // the WebSocket's own timeouts take over
    websocket::stream_base::timeout timeouts{};
    timeouts.handshake_timeout = limits.ws_handshake_timeout;
    timeouts.idle_timeout = limits.ws_idle_timeout;
    timeouts.keep_alive_pings = true;
    ws_.set_option(timeouts);
    ws_.set_option(
        websocket::stream_base::decorator([](websocket::response_type& res) { res.set(http::field::server, server_name); }));
    ws_.read_message_max(limits.max_message_bytes);
    ws_.auto_fragment(false);
    ws_.async_accept(req, beast::bind_front_handler(&WsSession::on_accept, shared_from_this()));
  }

  void shutdown() override {
    net::post(executor_, [self = shared_from_this()] {
      if (self->finished_ || self->closing_) return;
      self->closing_ = true;
      // Still handshaking: on_accept closes. Writing: on_write closes.
      if (self->client_ && !self->writing_) self->close();
    });
  }

  void abort() override {
    net::post(executor_, [self = shared_from_this()] { self->cut(); });
  }

  // Any thread: counts the reply against the bound, then queues it on the strand.
  void send(std::string text) {
    if (dropped_) return;
    const std::size_t n = text.size();
    const std::size_t before = queued_.fetch_add(n);
    // A reply bigger than the bound still goes out into an empty queue.
    if (before > 0 && before + n > server_.options.limits.max_queued_bytes) {
      queued_.fetch_sub(n);
      if (!dropped_.exchange(true)) abort();
      return;
    }
    net::post(executor_, [self = shared_from_this(), text = std::move(text)]() mutable { self->push(std::move(text)); });
  }

 private:
  Sink make_sink() {
    return [gate = server_.gate, weak = weak_from_this()](std::string text) {
      std::shared_lock lock(gate->mutex);
      if (!gate->open) return;
      if (auto self = weak.lock()) self->send(std::move(text));
    };
  }

  void on_accept(beast::error_code ec) {
    if (ec) return cut();
    if (closing_) return close();  // stopped during the handshake: the handler never hears of it
    client_ = server_.handler.connect(make_sink());
    read();
  }

  void read() { ws_.async_read(buffer_, beast::bind_front_handler(&WsSession::on_read, shared_from_this())); }

  void on_read(beast::error_code ec, std::size_t) {
    if (ec) return finish();
    if (!ws_.got_text()) {
      send(error_json("binary frames are not accepted"));
    } else {
      const auto data = buffer_.cdata();
      const std::string_view text(static_cast<const char*>(data.data()), data.size());
      try {
        server_.handler.handle(*client_, text);
      } catch (...) {  // handlers promise not to throw; the server stays up if one does
        send(R"({"type":"error","code":"internal","message":"the message handler failed"})");
      }
    }
    buffer_.consume(buffer_.size());
    read();  // after a cut this fails at once and finishes the session on its strand
  }

  void push(std::string text) {
    if (finished_ || dropped_ || closing_) {
      queued_.fetch_sub(text.size());
      return;
    }
    queue_.push_back(std::move(text));
    if (!writing_) write_next();
  }

  void write_next() {
    writing_ = true;
    ws_.text(true);
    ws_.async_write(net::buffer(queue_.front()), beast::bind_front_handler(&WsSession::on_write, shared_from_this()));
  }

  void on_write(beast::error_code ec, std::size_t) {
    writing_ = false;
    queued_.fetch_sub(queue_.front().size());
    queue_.pop_front();
    if (ec) return cut();
    if (closing_) return close();
    if (!queue_.empty()) write_next();
  }

  void close() {
    ws_.async_close(websocket::close_code::going_away, [self = shared_from_this()](beast::error_code) {});
  }

  // Pending reads and writes complete with an error; the read's completion
  // finishes the session.
  void cut() {
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
    if (!writing_) queue_.clear();
  }

  void finish() {
    if (finished_) return;
    finished_ = true;
    if (client_) server_.handler.disconnect(*client_);
  }

  Server::Impl& server_;
  net::any_io_executor executor_;  // the connection's strand
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buffer_;
  std::deque<std::string> queue_;  // replies; the front one is being written while writing_
  std::atomic<std::size_t> queued_{0};
  std::atomic<bool> dropped_{false};
  std::optional<std::uint64_t> client_;
  std::uint64_t id_ = 0;
  bool writing_ = false;
  bool closing_ = false;
  bool finished_ = false;
};

// ----------------------------------------------------------------------- HTTP

class HttpSession final : public Connection, public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Server::Impl& server, tcp::socket&& socket)
      : server_(server), stream_(std::move(socket)), buffer_(4 * server.options.limits.max_request_bytes) {}
  ~HttpSession() override {
    if (id_) server_.remove(id_);
  }

  void run() {
    id_ = server_.add(shared_from_this());
    net::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->read(); });
  }
  void shutdown() override { abort(); }
  void abort() override {
    net::post(stream_.get_executor(), [self = shared_from_this()] { self->stream_.close(); });
  }

 private:
  void read() {
    const auto& limits = server_.options.limits;
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(std::min<std::size_t>(limits.max_request_bytes, UINT32_MAX)));
    parser_->body_limit(limits.max_request_bytes);
    stream_.expires_after(limits.http_timeout);
    http::async_read(stream_, buffer_, *parser_, beast::bind_front_handler(&HttpSession::on_read, shared_from_this()));
  }

  void on_read(beast::error_code ec, std::size_t) {
    if (ec == http::error::header_limit)
      return reply(http::status::request_header_fields_too_large, "request header too large", 11, false, false);
    if (ec == http::error::body_limit) return reply(http::status::payload_too_large, "request body too large", 11, false, false);
    if (ec && ec.category() == beast::error_code(http::error::bad_target).category() && ec != http::error::end_of_stream &&
        ec != http::error::partial_message)
      return reply(http::status::bad_request, "malformed request", 11, false, false);
    if (ec) return;  // closed, reset, timed out: nothing to answer
    handle(parser_->release());
  }

  void handle(http::request<http::string_body> req) {
    const unsigned version = req.version();
    const bool keep_alive = req.keep_alive();
    const std::string_view target = view(req.target());
    if (websocket::is_upgrade(req)) {
      if (target.substr(0, target.find('?')) != "/ws") return reply(http::status::not_found, "not found", version, false, false);
      if (!origin_allowed(req, server_.options.allowed_origins))
        return reply(http::status::forbidden, "origin not allowed", version, false, false);
      // The connection now counts as the WebSocket's, before the 101 goes out.
      server_.remove(std::exchange(id_, 0));
      std::make_shared<WsSession>(server_, stream_.release_socket())->run(std::move(req));
      return;
    }
    const bool head = req.method() == http::verb::head;
    if (req.method() != http::verb::get && !head)
      return reply(http::status::method_not_allowed, "method not allowed", version, keep_alive, head);
    const Lookup found = lookup(server_.root, target);
    if (found.status != http::status::ok)
      return reply(found.status, found.status == http::status::not_found ? "not found" : "bad request", version, keep_alive,
                   head);

    beast::error_code ec;
    http::file_body::value_type body;
    body.open(found.file.c_str(), beast::file_mode::scan, ec);
    if (ec) return reply(http::status::not_found, "not found", version, keep_alive, head);
    const std::uint64_t size = body.size();
    auto fill = [&](auto& res) {
      res.set(http::field::server, server_name);
      res.set(http::field::content_type, mime_type(found.file));
      res.set("X-Content-Type-Options", "nosniff");
      // Vite names assets by content hash; only the page that names them must be revalidated.
      if (found.file.filename() == "index.html") res.set(http::field::cache_control, "no-cache");
      res.content_length(size);
      res.keep_alive(keep_alive);
    };
    if (head) {
      http::response<http::empty_body> res{http::status::ok, version};
      fill(res);
      return send(std::move(res));
    }
    http::response<http::file_body> res{std::piecewise_construct, std::make_tuple(std::move(body)),
                                        std::make_tuple(http::status::ok, version)};
    fill(res);
    send(std::move(res));
  }

  void reply(http::status status, std::string_view text, unsigned version, bool keep_alive, bool head) {
    http::response<http::string_body> res{status, version};
    res.set(http::field::server, server_name);
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    if (status == http::status::method_not_allowed) res.set(http::field::allow, "GET, HEAD");
    res.keep_alive(keep_alive);
    res.body() = std::string(text) + "\n";
    res.prepare_payload();
    if (head) res.body().clear();  // the length stays, as HEAD requires
    send(std::move(res));
  }

  template <class Body>
  void send(http::response<Body>&& res) {
    auto message = std::make_shared<http::response<Body>>(std::move(res));
    response_ = message;
    stream_.expires_after(server_.options.limits.http_timeout);
    http::async_write(stream_, *message,
                      [self = shared_from_this(), close = message->need_eof()](beast::error_code ec, std::size_t) {
                        self->response_.reset();
                        if (ec) return;
                        if (close) {
                          self->stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
                          return;
                        }
                        self->read();
                      });
  }

  Server::Impl& server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<void> response_;  // the message being written
  std::uint64_t id_ = 0;
};

}  // namespace

// ------------------------------------------------------------ server internals

void Server::Impl::accept() { acceptor.async_accept(net::make_strand(ioc), beast::bind_front_handler(&Impl::on_accept, this)); }

void Server::Impl::on_accept(beast::error_code ec, tcp::socket socket) {
  if (stopping || !acceptor.is_open()) return;
  if (ec) {
    // Out of descriptors and the like: pause instead of spinning.
    accept_pause.expires_after(std::chrono::milliseconds(100));
    accept_pause.async_wait([this](beast::error_code e) {
      if (!e && !stopping) accept();
    });
    return;
  }
  if (count() >= options.limits.max_connections)
    refuse(std::move(socket));
  else
    std::make_shared<HttpSession>(*this, std::move(socket))->run();
  accept();
}

void Server::Impl::begin_stop() {
  beast::error_code ec;
  acceptor.close(ec);
  accept_pause.cancel();
  signals.clear(ec);  // a second Ctrl-C ends the process the default way
  const auto connections = live();
  if (connections.empty()) return;
  for (const auto& c : connections) c->shutdown();
  grace.expires_after(options.limits.stop_grace);
  grace.async_wait([this](beast::error_code e) {
    if (e) return;
    for (const auto& c : live()) c->abort();
  });
}

// ---------------------------------------------------------------- public API

bool is_loopback_address(const std::string& address) {
  boost::system::error_code ec;
  const auto a = net::ip::make_address(address, ec);
  if (ec) return false;
  if (a.is_v4()) return a.to_v4().is_loopback();
  const auto v6 = a.to_v6();
  return v6.is_loopback() || (v6.is_v4_mapped() && net::ip::make_address_v4(net::ip::v4_mapped, v6).is_loopback());
}

Server::Server(MessageHandler& handler, ServerOptions options) {
  boost::system::error_code ec;
  net::ip::make_address(options.address, ec);
  if (ec) throw InvalidArgument("address '" + options.address + "' is not an IP address (e.g. 127.0.0.1 or ::1)");
  if (!options.allow_remote && !is_loopback_address(options.address))
    throw InvalidArgument("address " + options.address + " is reachable from other machines: serving it needs --allow-remote");
  if (options.threads < 1 || options.threads > 16)
    throw InvalidArgument("server threads is " + std::to_string(options.threads) + "; allowed 1 … 16");
  const auto& l = options.limits;
  if (l.max_message_bytes == 0 || l.max_connections == 0 || l.max_queued_bytes == 0 || l.max_request_bytes == 0)
    throw InvalidArgument("server limits must be positive");
  impl_ = std::make_unique<Impl>(handler, std::move(options));
}

Server::~Server() {
  {
    std::unique_lock lock(impl_->gate->mutex);
    impl_->gate->open = false;
  }
  impl_->stopping = true;
  impl_->torn_down = true;
  impl_->ioc.stop();
}

std::uint16_t Server::start() {
  Impl& s = *impl_;
  if (s.started) throw InvalidArgument("the studio server is already started");
  const fs::path web(s.options.web_root);
  std::error_code fec;
  if (s.options.web_root.empty() || !fs::is_regular_file(web / "index.html", fec))
    throw IoError("front end not found: '" + s.options.web_root +
                  "' has no index.html (build it with `make demo`, or pass --web DIR)");
  s.root = fs::canonical(web, fec);
  if (fec) throw IoError("web root '" + s.options.web_root + "': " + fec.message());

  const tcp::endpoint wanted(net::ip::make_address(s.options.address), s.options.port);
  const std::string where = s.options.address + ":" + std::to_string(s.options.port);
  beast::error_code ec;
  s.acceptor.open(wanted.protocol(), ec);
  if (!ec) s.acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor.bind(wanted, ec);
  if (!ec) s.acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) throw IoError("cannot listen on " + where + ": " + ec.message());
  s.endpoint = s.acceptor.local_endpoint();
  s.started = true;
  net::post(s.strand, [&s] { s.accept(); });
  if (s.options.stop_on_signals) {
    s.signals.add(SIGINT);
    s.signals.add(SIGTERM);
    s.signals.async_wait([this](beast::error_code e, int) {
      if (!e) stop();
    });
  }
  return s.endpoint.port();
}

void Server::run() {
  Impl& s = *impl_;
  if (!s.started) throw InvalidArgument("the studio server must be started before it runs");
  std::vector<std::thread> extra;
  for (int i = 1; i < s.options.threads; ++i) extra.emplace_back([&s] { s.ioc.run(); });
  s.ioc.run();
  for (auto& t : extra) t.join();
}

void Server::stop() {
  if (impl_->stopping.exchange(true)) return;
  net::post(impl_->strand, [s = impl_.get()] { s->begin_stop(); });
}

std::string Server::url() const {
  const auto a = impl_->endpoint.address();
  const std::string host = a.is_v6() ? "[" + a.to_string() + "]" : a.to_string();
  return "http://" + host + ":" + std::to_string(impl_->endpoint.port()) + "/";
}

std::size_t Server::connections() const { return impl_->count(); }

}  // namespace texel::studio
