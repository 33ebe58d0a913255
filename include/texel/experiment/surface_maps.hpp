// The player maps of a 2-D session's intervals (task oddity-2d), made one way
// for every front end that plays them: the terminal's 2-D display presenter
// (presenter.hpp) and the studio's participant page. A path-indexed map is
// made when asked (a fraction of a millisecond); a static field's friction
// bitmap is rendered once (about a second on tablet-2d) from the field's
// shared preparation and kept, the most recently shown first, up to eight
// (every static field of a shipped 2-D protocol).
//
// preload() renders, on a background thread at a lower priority, every
// bitmap a session of the protocol will show, in the order it shows them (a
// shadow session of the same protocol and context asks the same questions:
// an oddity-2d trial's surfaces do not depend on the answers given), so a
// trial finds its bitmaps ready. Thread-safe: a bitmap asked while another
// thread renders it waits for that rendering instead of repeating it.
#pragma once

#include <atomic>
#include <future>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "texel/experiment/session.hpp"
#include "texel/player2d.hpp"

namespace texel::experiment {

class SurfaceMaps {
 public:
  SurfaceMaps() = default;
  ~SurfaceMaps() { stop(); }
  SurfaceMaps(const SurfaceMaps&) = delete;
  SurfaceMaps& operator=(const SurfaceMaps&) = delete;

  /// A map of the interval for a player to own (a copy of the cached bitmap,
  /// a few milliseconds). Throws InvalidArgument for a surface that is not a
  /// version-4 document of one region on a display with a bitmap grid.
  std::unique_ptr<const PlayerMap2D> map(const SurfaceStimulus& s);
  /// Renders the question's bitmaps now unless they are ready (waits for one
  /// the preload is rendering), so showing its intervals costs a copy.
  void prepare(const Question& question);
  /// Starts the preload (see the banner); stop() or the destructor ends it.
  /// No-op when already started.
  void preload(const Protocol& protocol, const SessionContext& context);
  /// Ends the preload (waits for at most the bitmap being rendered).
  void stop();
  /// Whether the preload has finished (every bitmap it could keep rendered).
  [[nodiscard]] bool preloaded() const { return preloaded_.load(); }
  /// Friction bitmaps rendered by the preload, and for a trial (prepare()
  /// or map(): each one a participant waited for).
  struct Counts {
    int preloaded = 0, at_trial = 0;
  };
  [[nodiscard]] Counts counts() const { return {rendered_ahead_.load(), rendered_when_shown_.load()}; }

  static constexpr std::size_t cache_size = 8;

 private:
  using MapFuture = std::shared_future<std::shared_ptr<const PlayerMap2D>>;
  std::shared_ptr<const PlayerMap2D> bitmap(const std::string& document_json, bool shown);
  void render_ahead(Session shadow, const std::stop_token& stop);

  std::mutex mutex_;                                      // guards bitmaps_ (the preload thread fills it)
  std::list<std::pair<std::string, MapFuture>> bitmaps_;  // most recently shown first
  std::atomic<bool> preloaded_{false};
  std::atomic<int> rendered_ahead_{0}, rendered_when_shown_{0};
  std::jthread preloader_;  // last: stopped and joined before the bitmaps go
};

}  // namespace texel::experiment
