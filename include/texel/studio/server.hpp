// Texel Studio's transport: HTTP for the built front end and a WebSocket at
// /ws whose text frames go to a MessageHandler (handler.hpp). Only bytes move
// here; every message's meaning lives in the handler (the Service).
//
// Design (Boost.Beast over one io_context, docs/studio.md "Server"):
// - Threads. run() drives the io_context on `threads` threads; every
//   connection lives on its own strand, so its reads, writes and handler
//   calls never overlap. handler.handle() runs on that strand: a handler
//   must answer cheap messages quickly and hand slow ones to its own workers.
// - Replies. A client's Sink may be called from any thread: it counts the
//   text against the connection's outgoing bound, then posts it to the
//   strand's write queue. A client that stops reading while replies pile up
//   past `max_queued_bytes` is disconnected; memory stays bounded. Sinks of
//   closed connections (and of a destroyed server) do nothing.
// - Lifetime. connect() and disconnect() pair exactly once per WebSocket;
//   disconnect() is called on the connection's strand when it ends (closed,
//   reset, timed out, over a limit, or the server stopping). The handler
//   must outlive the Server.
// - Static files come from one root, resolved and checked, never
//   concatenated: percent-decoded targets with `..`, empty segments, NUL or
//   backslashes are refused (400); the resolved path must stay inside the
//   canonical root (symlinks leading out give 404); directories give 404
//   except "/" (index.html); no listing.
// - Browsers. A WebSocket upgrade carrying an Origin header is accepted only
//   when the origin is this server as the browser addressed it
//   ("http://" + Host) and Host is an IP literal or "localhost" (defeats DNS
//   rebinding), or an origin listed in `allowed_origins`. A hostile page in
//   the user's browser thus cannot drive the studio. Non-browser clients
//   (no Origin) are accepted.
// - Timeouts reap slow or half-open peers: an HTTP request must arrive
//   whole within `http_timeout` (slowloris); a WebSocket that receives
//   nothing for half of `ws_idle_timeout` is pinged and closed if still
//   silent at `ws_idle_timeout`. Opening and closing handshakes are bounded
//   by `ws_handshake_timeout`; on stop(), peers get `stop_grace` to answer
//   the close ("going away") before they are cut. A trade-off: a peer trickling one valid byte
//   at a time keeps its connection; `max_connections` bounds the cost.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "texel/studio/handler.hpp"

namespace texel::studio {

struct ServerLimits {
  std::size_t max_message_bytes = 4u << 20;        ///< largest WebSocket message accepted (bigger: closed, code 1009)
  std::size_t max_connections = 32;                ///< TCP connections at once (HTTP + WebSocket); beyond: 503 and close
  std::size_t max_queued_bytes = 16u << 20;        ///< per-connection replies not yet written; beyond: the client is dropped
  std::size_t max_request_bytes = 16u << 10;       ///< HTTP request header and body limit, each (431/413 beyond)
  std::chrono::milliseconds http_timeout{10'000};  ///< to receive one whole HTTP request, and to write a response
  std::chrono::milliseconds ws_handshake_timeout{5'000};  ///< WebSocket opening / closing handshake
  std::chrono::milliseconds ws_idle_timeout{30'000};      ///< silence before a WebSocket is dropped (pinged at half)
  std::chrono::milliseconds stop_grace{1'000};            ///< stop() waits this long for closing handshakes, then cuts
};

struct ServerOptions {
  std::string address = "127.0.0.1";         ///< IP literal to bind; non-loopback needs allow_remote
  std::uint16_t port = 0;                    ///< 0 picks a free port
  std::string web_root;                      ///< the built front end (must hold index.html)
  bool allow_remote = false;                 ///< permit a non-loopback address
  std::vector<std::string> allowed_origins;  ///< extra browser origins allowed to open /ws, e.g. "http://localhost:5173"
  int threads = 2;                           ///< io threads run() uses, 1 … 16
  bool stop_on_signals = false;              ///< SIGINT / SIGTERM call stop() (the CLI sets this)
  ServerLimits limits;
};

class Server {
 public:
  /// Validates the options (InvalidArgument names the field). Binds nothing yet.
  Server(MessageHandler& handler, ServerOptions options);
  /// Stops if running and drops every connection (each gets its disconnect()).
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Checks the web root and binds the address; returns the bound port.
  /// Throws IoError naming the path or address (missing front end, port in use).
  std::uint16_t start();
  /// Serves until stop(); returns once every connection has closed (within
  /// stop_grace; the rest are cut).
  void run();
  /// Thread-safe, idempotent; may be called before, during or after run().
  void stop();

  /// "http://ADDRESS:PORT/" once started (IPv6 in brackets).
  [[nodiscard]] std::string url() const;
  /// Open TCP connections right now (HTTP and WebSocket).
  [[nodiscard]] std::size_t connections() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// True for 127.0.0.0/8, ::1 and IPv4-mapped loopback; false for anything
/// else, including text that is not an IP address.
[[nodiscard]] bool is_loopback_address(const std::string& address);

}  // namespace texel::studio
