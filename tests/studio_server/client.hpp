// A small test client for the studio server: raw HTTP over a socket (so a
// test can send any bytes, stall or reset), and a WebSocket client on Beast
// (client.cpp, the tests' only Beast translation unit). Every call has a
// time limit, so a misbehaving server fails a test instead of hanging it.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace texel::test_support {

using namespace std::chrono_literals;

/// A TCP connection to 127.0.0.1:port with a receive timeout (-1 on failure).
int tcp_connect(std::uint16_t port, std::chrono::milliseconds timeout = 5s);
/// Sends all of `bytes`; false if the peer is gone.
bool send_all(int fd, const std::string& bytes);
/// Reads until the peer closes or `timeout` passes.
std::string read_until_close(int fd, std::chrono::milliseconds timeout = 5s);
/// Closes with a reset (SO_LINGER 0) instead of an orderly FIN.
void reset_close(int fd);

struct HttpReply {
  int status = 0;       ///< 0: no answer
  std::string headers;  ///< the header block
  std::string body;
  /// Value of header `name` (lower-case; matched case-insensitively), "" if absent.
  [[nodiscard]] std::string header(const std::string& name) const;
};

/// Sends `request` verbatim and parses the reply.
HttpReply http_raw(std::uint16_t port, const std::string& request);
/// `METHOD target HTTP/1.1` with Host and Connection: close.
HttpReply http_request(std::uint16_t port, const std::string& method, const std::string& target);

class WsClient {
 public:
  WsClient();
  ~WsClient();
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;

  /// Opens ws://127.0.0.1:port + target. `host` replaces the Host header,
  /// `origin` adds an Origin header. False on failure; see status(), error().
  bool connect(std::uint16_t port, const std::string& target = "/ws", const std::string& origin = "",
               const std::string& host = "");
  bool send_text(const std::string& text);
  bool send_binary(const std::string& bytes);
  /// Writes raw bytes on the socket beneath the WebSocket (hand-made frames).
  bool send_raw(const std::string& bytes);
  /// The next message, or nullopt on close, error or timeout (after which
  /// the client is unusable). close_code() tells why it closed.
  std::optional<std::string> read(std::chrono::milliseconds timeout = 5s);
  /// Closes with the WebSocket closing handshake.
  void close();
  /// Drops the TCP connection with a reset.
  void reset();

  [[nodiscard]] int status() const;      ///< HTTP status of a refused handshake (e.g. 403), 101 when open
  [[nodiscard]] int close_code() const;  ///< close code the server sent, 0 if none
  [[nodiscard]] std::string error() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A masked client frame header (FIN set) for `payload_length` bytes;
/// opcode 1 = text, 2 = binary. The mask key is zero, so payload bytes go as-is.
std::string ws_frame_header(std::uint64_t payload_length, int opcode = 1);

}  // namespace texel::test_support
