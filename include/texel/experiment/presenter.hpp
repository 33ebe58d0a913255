// Stimulus presentation: the textures of a trial played through the
// existing player backends (null, audio, serial display), switching when the
// participant selects one (experiments.md: the participant may switch among
// the stimuli freely).
//
// A Presenter owns a backend and a Player for the whole session. show()
// prepares the selected document's map on the control thread and swaps it
// into the real-time player (which crossfades); blank() swaps in silence.
// The finger: with a serial display the display senses it; otherwise
// (sound-card actuators, null) the texture is played under a simulated
// back-and-forth swipe at `swipe_speed_mm_s`, like `texel play`, so it can be
// felt or heard. pump() feeds that finger and frees retired maps: call it
// often (every ≤ 20 ms) from the control thread.
//
// Trade-off: one control thread, no callback into the engine; the real-time
// side is the player's (no allocation, locks or I/O).
#pragma once

#include <cstddef>
#include <list>
#include <memory>
#include <string>
#include <utility>

#include "texel/sinks.hpp"

namespace texel::experiment {

struct PresenterOptions {
  std::string backend = "null";  ///< "null", "audio", "serial:PATH"
  std::string audio_device;      ///< PortAudio device (index or name substring); empty = default
  double rate_hz = 48000.0;      ///< audio / null output rate (Hz)
  std::size_t block_frames = 64;
  double swipe_speed_mm_s = 100.0;  ///< simulated finger speed (mm/s), > 0
};

class Presenter {
 public:
  /// Opens and starts the backend (throws InvalidArgument / IoError naming it).
  explicit Presenter(const PresenterOptions& options);
  ~Presenter();
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  /// Plays the texture document (a Texel document as JSON text).
  void show(const std::string& document_json);
  /// Silence (between trials, during the working-memory matrix).
  void blank();
  /// Feeds the simulated finger ahead of the player and frees retired maps.
  void pump();
  /// Stops the backend; statistics stay readable. Safe to call twice.
  void stop();

  [[nodiscard]] BackendStats stats();
  [[nodiscard]] std::string describe() const;
  /// The backend's block period (s), for reporting worst-block fractions.
  [[nodiscard]] double block_period_s() const;
  /// Maps shown so far.
  [[nodiscard]] std::size_t shown() const { return shown_; }
  /// An error the backend reported (e.g. the serial link dropped); empty if none.
  [[nodiscard]] std::string error() const;

 private:
  static constexpr std::size_t cache_size = 8;
  std::list<std::pair<std::string, std::unique_ptr<const PlayerMap>>> cache_;  // most recent first
  PresenterOptions options_;
  std::unique_ptr<Player> player_;
  std::unique_ptr<Backend> backend_;
  double next_finger_s_ = 0.0;
  double period_s_ = 0.0;
  std::size_t shown_ = 0;
  bool running_ = false;
};

}  // namespace texel::experiment
