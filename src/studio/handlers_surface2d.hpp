// What the 2-D page's handlers share (internal; handlers_surface2d.cpp:
// surface2d.view / surface2d.scan; handlers_feel2d.cpp: the 2-D feel pad and
// the device's hand-over): the prepared 2-D document and the state of the
// pad's player.
#pragma once

#include <array>
#include <atomic>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "messages.hpp"
#include "texel/player2d.hpp"
#include "texel/serial_link.hpp"
#include "texel/sinks.hpp"
#include "texel/surface2d.hpp"

namespace texel::studio::detail {

/// A prepared 2-D document and the temporary directory its images live in.
struct Prepared {
  Document doc;
  std::optional<Surface2D> surface;
  std::filesystem::path image_dir;
  Prepared() = default;
  Prepared(const Prepared&) = delete;
  Prepared& operator=(const Prepared&) = delete;
  ~Prepared() {
    std::error_code ec;
    if (!image_dir.empty()) std::filesystem::remove_all(image_dir, ec);
  }
};

struct Surface2DState {
  std::mutex cache_mutex;
  std::string cache_key;
  std::shared_ptr<const Prepared> cache;

  // The pad's player, guarded by State::feel_mutex (the hand-over of the device needs both sides).
  std::unique_ptr<Player2D> player;  // created at the first feel2d.select
  std::unique_ptr<Backend> backend;  // declared after the player: stopped first; null while the Presenter has the device
  std::string mode;
  std::uint64_t finger_client = 0;
  double finger_x = 0.0, finger_y = 0.0, last_t = 0.0;
  bool finger_down = false;
  std::uint64_t samples = 0;

  // A serial display's own finger (protocol 1.1): while the pad holds a display
  // that reports it, a reader thread places each report on the player's clock
  // and pushes it (under State::feel_mutex), and the pad only shows it.
  bool display_finger = false;
  std::uint64_t reports = 0;                // pushed so far
  double display_x = 0.0, display_y = 0.0;  // the newest report
  bool display_touch = false;
  std::vector<std::array<double, 3>> trail;  // reports since the last feel2d.state: x, y, touch (bounded)
  ReportTimeline timeline;                   // the reader's
  std::atomic<bool> reader_stop{false};      // the reader gives up waiting for feel_mutex
  std::optional<ReportReader> reader;        // its error stays readable until the next reader starts

  Surface2DState() = default;
  Surface2DState(const Surface2DState&) = delete;
  Surface2DState& operator=(const Surface2DState&) = delete;
  ~Surface2DState() { stop_reader(); }
  /// Stops the reader thread (the caller may hold feel_mutex: the reader never waits on it).
  void stop_reader() {
    reader_stop = true;
    if (reader) reader->stop();
    reader_stop = false;
  }
};

/// The document of a 2-D message with its coarse images resolved to the bytes
/// sent along, prepared (cached: zooming and panning re-use it).
std::shared_ptr<const Prepared> prepared(State& s, const Fields& f, const std::string& type);

/// The message's "region" (default 0), refused if the document has no such region.
std::size_t region_of(const Fields& f, const Prepared& p, const std::string& type);

}  // namespace texel::studio::detail
