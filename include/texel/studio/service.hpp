// Texel Studio's engine side: every message the browser sends, answered by
// the library. No sockets here (server.hpp carries the bytes), so the whole
// message surface is testable and fuzzable without a network.
//
// A Service owns what the studio shares between browser tabs: the player
// behind the "Feel it" strip and the participant screens (one backend:
// null, audio or serial display), the experiment store and the sessions
// being run. Clients are numbered by the server; each message is one JSON
// object with a "type" (docs/studio.md lists them all, with limits).
//
// Threads. handle() may be called from any thread. Cheap messages (hello,
// finger positions, backend state) are answered before handle() returns; slow
// ones (designing a map, encoding, experiment steps) run on the service's
// own worker threads and answer through the client's Sink later. Design
// requests coalesce: while one is being computed, newer ones from the same
// client replace older queued ones (a dragged slider wants the latest map,
// not every intermediate one). Messages of one client are answered in the
// order they were sent within each lane (docs/studio.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "texel/studio/handler.hpp"

namespace texel::studio {

struct ServiceOptions {
  std::string db_path = "texel-studio.db";  ///< experiment store (created on first use)
  std::string backend = "null";             ///< "null", "audio" or "serial:PATH"
  std::string audio_device;                 ///< PortAudio device for "audio" (index or name substring)
  /// Feel-it and participant screens: how the player respects the shown
  /// document's display response, "limit" ([choice], the default) or "off"
  /// (experiment/presenter.hpp, docs/format.md "Frequency response").
  std::string response = "limit";
  /// Output channels of the backend, one per actuator of a multi-actuator
  /// display, 1 … 64 (PresenterOptions::channels; `texel studio --channels`).
  std::size_t channels = 1;
  std::string protocols_dir;                 ///< shipped protocols offered in the experimenter view ("" = none)
  std::size_t max_message_bytes = 4u << 20;  ///< larger messages are refused
  double max_messages_per_s = 2000.0;        ///< per client, token bucket (burst = one second's worth)
  /// Largest device map (samples) and texel count a client's document may
  /// ask to render; tpad is 19,200 samples. Bounds memory and time per message.
  std::size_t max_map_samples = std::size_t{1} << 21;
};

class Service final : public MessageHandler {
 public:
  /// Opens the backend (throws InvalidArgument / IoError naming it). The
  /// store is opened lazily on the first experiment message.
  explicit Service(ServiceOptions options);
  /// Stops the workers and the backend; sessions in progress stay
  /// resumable (every answered trial is already committed).
  ~Service() override;
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  /// A browser connected. Returns the client id used by handle()/disconnect().
  std::uint64_t connect(Sink sink) override;
  /// Handles one text message. Never throws: malformed or hostile input gets
  /// an {"type":"error",...} reply through the client's sink.
  void handle(std::uint64_t client, std::string_view text) override;
  /// The client went away (closed, reset or timed out): its queued work is
  /// dropped, its finger lifts. Sessions it was running stay open.
  void disconnect(std::uint64_t client) override;

  /// One line for the console ("null 48000 Hz, 64 frames").
  [[nodiscard]] std::string describe() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace texel::studio
