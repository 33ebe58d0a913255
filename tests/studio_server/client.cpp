// The studio server tests' client (client.hpp): POSIX sockets for raw HTTP,
// Beast for the WebSocket. Beast's synchronous calls have no timeouts, so
// every WebSocket operation runs asynchronously on a private io_context for
// at most its time limit.
#include "client.hpp"

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>

namespace texel::test_support {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

int tcp_connect(std::uint16_t port, std::chrono::milliseconds timeout) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  timeval tv{static_cast<time_t>(timeout.count() / 1000), static_cast<suseconds_t>((timeout.count() % 1000) * 1000)};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool send_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

std::string read_until_close(int fd, std::chrono::milliseconds timeout) {
  std::string out;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  char buf[65536];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

void reset_close(int fd) {
  linger l{1, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_LINGER, &l, sizeof l);
  ::close(fd);
}

std::string HttpReply::header(const std::string& name) const {
  std::string folded = headers;
  std::transform(folded.begin(), folded.end(), folded.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::string key = "\r\n" + name + ":";
  const auto at = folded.find(key);
  if (at == std::string::npos) return "";
  auto begin = at + key.size();
  while (begin < headers.size() && headers[begin] == ' ') ++begin;
  return headers.substr(begin, headers.find("\r\n", begin) - begin);
}

HttpReply http_raw(std::uint16_t port, const std::string& request) {
  HttpReply r;
  const int fd = tcp_connect(port);
  if (fd < 0) return r;
  send_all(fd, request);
  const std::string raw = read_until_close(fd);
  ::close(fd);
  const auto end = raw.find("\r\n\r\n");
  if (raw.rfind("HTTP/1.", 0) != 0 || end == std::string::npos) return r;
  r.status = std::atoi(raw.c_str() + 9);
  r.headers = raw.substr(0, end + 2);
  r.body = raw.substr(end + 4);
  return r;
}

HttpReply http_request(std::uint16_t port, const std::string& method, const std::string& target) {
  return http_raw(
      port, method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\nConnection: close\r\n\r\n");
}

std::string ws_frame_header(std::uint64_t payload_length, int opcode) {
  std::string h;
  h += static_cast<char>(0x80 | opcode);
  if (payload_length < 126) {
    h += static_cast<char>(0x80 | payload_length);
  } else if (payload_length < 65536) {
    h += static_cast<char>(0x80 | 126);
    h += static_cast<char>(payload_length >> 8);
    h += static_cast<char>(payload_length & 0xff);
  } else {
    h += static_cast<char>(0x80 | 127);
    for (int i = 7; i >= 0; --i) h += static_cast<char>((payload_length >> (8 * i)) & 0xff);
  }
  h += std::string(4, '\0');  // mask key 0
  return h;
}

struct WsClient::Impl {
  net::io_context ioc;
  websocket::stream<beast::tcp_stream> ws{ioc};
  beast::flat_buffer buffer;
  websocket::response_type response;
  std::string error;
  bool open = false;

  // Runs one asynchronous operation for at most `timeout`; on timeout the
  // socket is cancelled and the operation completes with an error.
  template <class Start>
  beast::error_code run(std::chrono::milliseconds timeout, Start start) {
    beast::error_code result = net::error::would_block;
    bool done = false;
    start([&](beast::error_code ec, auto&&...) {
      result = ec;
      done = true;
    });
    ioc.restart();
    ioc.run_for(timeout);
    if (!done) {
      beast::error_code ignored;
      beast::get_lowest_layer(ws).socket().cancel(ignored);
      ioc.restart();
      ioc.run();
      result = beast::error::timeout;
    }
    if (result) error = result.message();
    return result;
  }
};

WsClient::WsClient() : impl_(std::make_unique<Impl>()) {}
WsClient::~WsClient() = default;

bool WsClient::connect(std::uint16_t port, const std::string& target, const std::string& origin, const std::string& host) {
  beast::error_code ec;
  beast::get_lowest_layer(impl_->ws).socket().connect(tcp::endpoint(net::ip::address_v4::loopback(), port), ec);
  if (ec) {
    impl_->error = ec.message();
    return false;
  }
  if (!origin.empty())
    impl_->ws.set_option(
        websocket::stream_base::decorator([origin](websocket::request_type& req) { req.set(http::field::origin, origin); }));
  const std::string h = host.empty() ? "127.0.0.1:" + std::to_string(port) : host;
  ec = impl_->run(5s, [&](auto handler) { impl_->ws.async_handshake(impl_->response, h, target, handler); });
  impl_->open = !ec;
  return impl_->open;
}

bool WsClient::send_text(const std::string& text) {
  impl_->ws.text(true);
  return !impl_->run(5s, [&](auto handler) { impl_->ws.async_write(net::buffer(text), handler); });
}

bool WsClient::send_binary(const std::string& bytes) {
  impl_->ws.binary(true);
  return !impl_->run(5s, [&](auto handler) { impl_->ws.async_write(net::buffer(bytes), handler); });
}

bool WsClient::send_raw(const std::string& bytes) {
  beast::error_code ec;
  net::write(beast::get_lowest_layer(impl_->ws).socket(), net::buffer(bytes), ec);
  return !ec;
}

std::optional<std::string> WsClient::read(std::chrono::milliseconds timeout) {
  impl_->buffer.consume(impl_->buffer.size());
  if (impl_->run(timeout, [&](auto handler) { impl_->ws.async_read(impl_->buffer, handler); })) return std::nullopt;
  return beast::buffers_to_string(impl_->buffer.data());
}

void WsClient::close() {
  impl_->run(2s, [&](auto handler) { impl_->ws.async_close(websocket::close_code::normal, handler); });
}

void WsClient::reset() {
  auto& socket = beast::get_lowest_layer(impl_->ws).socket();
  beast::error_code ec;
  socket.set_option(net::socket_base::linger(true, 0), ec);
  socket.close(ec);
}

int WsClient::status() const { return static_cast<int>(impl_->response.result_int()); }
int WsClient::close_code() const { return static_cast<int>(impl_->ws.reason().code); }
std::string WsClient::error() const { return impl_->error; }

}  // namespace texel::test_support
