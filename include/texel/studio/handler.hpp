// What the studio server carries messages to: connect a client with a sink
// for its replies, hand over its text messages, tell when it leaves. The
// Service (service.hpp) is the real handler; the server knows only this, so
// its transport tests can run against small fakes as well.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace texel::studio {

/// Where a client's replies go. Called from handler threads; must be
/// thread-safe and must not block for long (the server queues the text).
using Sink = std::function<void(std::string text)>;

class MessageHandler {
 public:
  virtual ~MessageHandler() = default;
  /// A browser connected. Returns the client id used by handle()/disconnect().
  virtual std::uint64_t connect(Sink sink) = 0;
  /// Handles one text message. Never throws: malformed or hostile input gets
  /// an {"type":"error",...} reply through the client's sink.
  virtual void handle(std::uint64_t client, std::string_view text) = 0;
  /// The client went away (closed, reset or timed out).
  virtual void disconnect(std::uint64_t client) = 0;
};

}  // namespace texel::studio
