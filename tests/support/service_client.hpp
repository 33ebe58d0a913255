// A client of a studio MessageHandler (texel::studio::Service) for tests:
// a capturing sink whose replies a test waits for, and ask() = send with a
// fresh id and wait for the reply to it. TEXEL_STUDIO_TEST_TRACE=1 prints
// each message's time.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "texel/studio/service.hpp"

namespace texel::test_support {

using namespace std::chrono_literals;
using json = nlohmann::json;

/// Collects a client's replies; waits for them.
struct Inbox {
  std::mutex m;
  std::condition_variable cv;
  std::vector<json> replies;
  std::function<void(const json&)> on_reply;  // runs inside the sink (before the service goes on)

  texel::studio::Sink sink() {
    return [this](std::string text) {
      json j = json::parse(text);  // every reply must be valid JSON
      if (on_reply) on_reply(j);
      std::lock_guard lock(m);
      replies.push_back(std::move(j));
      cv.notify_all();
    };
  }
  /// The first reply (removed) matching `pred`, waiting up to `timeout`.
  json take(const std::function<bool(const json&)>& pred, std::chrono::milliseconds timeout = 20s) {
    std::unique_lock lock(m);
    json out;
    const bool found = cv.wait_for(lock, timeout, [&] {
      for (auto it = replies.begin(); it != replies.end(); ++it)
        if (pred(*it)) {
          out = *it;
          replies.erase(it);
          return true;
        }
      return false;
    });
    if (!found) ADD_FAILURE() << "no matching reply within the timeout";
    return out;
  }
  json reply_to(const json& id, std::chrono::milliseconds timeout = 20s) {
    return take([&](const json& j) { return j.contains("id") && j["id"] == id; }, timeout);
  }
  std::size_t count() {
    std::lock_guard lock(m);
    return replies.size();
  }
};

/// One connected client.
struct Client {
  texel::studio::MessageHandler& h;
  Inbox inbox;
  std::uint64_t id;
  int next_id = 1;
  explicit Client(texel::studio::MessageHandler& handler) : h(handler), id(h.connect(inbox.sink())) {}
  ~Client() { h.disconnect(id); }  // the sink captures the inbox: no replies after this
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  /// Sends `msg` with a fresh id and waits for its reply.
  json ask(json msg, std::chrono::milliseconds timeout = 20s) {
    const int i = next_id++;
    msg["id"] = i;
    const auto t0 = std::chrono::steady_clock::now();
    h.handle(id, msg.dump());
    json r = inbox.reply_to(i, timeout);
    if (std::getenv("TEXEL_STUDIO_TEST_TRACE"))
      std::printf("%8.2f ms %s\n", std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count(),
                  msg.value("type", "?").c_str());
    return r;
  }
  json raw(std::string_view text) {
    h.handle(id, text);
    return inbox.take([](const json&) { return true; });
  }
};

}  // namespace texel::test_support
