// Stimulus presentation: the textures of a trial played through the
// existing player backends (null, audio, serial display), switching when the
// participant selects one (docs/procedures.md §6: the participant may switch among
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
// External finger (FingerSource::external, the studio's "Feel it" strip): the
// positions come from outside (a browser's pointer) through push_finger(),
// which stamps each sample with the player's clock on arrival plus a small
// lead, so the player interpolates towards it instead of extrapolating; pump()
// then feeds nothing and only frees retired maps.
//
// The display's frequency response (player.hpp, docs/format.md "Frequency
// response"): every stimulus carries its document's device response
// (PlayerMap::from_document), so the one player respects the response of
// the device each document is for — in a session the protocol's device, in
// the studio the designed document's — switching at the map swap without
// rebuilding the player. response_handling [choice] limit (off: as before,
// flat). With a serial display the player streams at 1 kHz, below any
// built-in profile's limit (tpad: 3.98 kHz), so nothing is filtered there.
//
// Trade-off: one control thread, no callback into the engine; the real-time
// side is the player's (no allocation, locks or I/O).
#pragma once

#include <cstddef>
#include <list>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "texel/sinks.hpp"

namespace texel::experiment {

/// Where finger positions come from (see the banner).
enum class FingerSource { simulated, external };

struct PresenterOptions {
  std::string backend = "null";  ///< "null", "audio", "serial:PATH"
  std::string audio_device;      ///< PortAudio device (index or name substring); empty = default
  double rate_hz = 48000.0;      ///< audio / null output rate (Hz)
  std::size_t block_frames = 64;
  double swipe_speed_mm_s = 100.0;  ///< simulated finger speed (mm/s), > 0
  FingerSource finger = FingerSource::simulated;
  /// External finger: a sample is due this long after it arrives (s), 0 … 0.1.
  /// Longer hides network jitter, shorter feels more direct.
  double finger_lead_s = 0.005;
  /// How the player respects each stimulus's display response (see the
  /// banner). [choice] limit; off plays flat.
  ResponseHandling response_handling = ResponseHandling::limit;
  /// limit: attenuation (dB) at which the display no longer reproduces, 3 … 60 [20].
  double response_limit_db = 20.0;
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
  /// Plays a map prepared by the caller (PlayerMap::from_document, which
  /// carries the device's response), so a front end shared by several
  /// threads can render outside its lock.
  void show(std::unique_ptr<const PlayerMap> map);
  /// Silence (between trials, during the working-memory matrix).
  void blank();
  /// Feeds the simulated finger ahead of the player (simulated mode) and
  /// frees retired maps.
  void pump();
  /// External finger mode: queues one sample (position in device mm, finger
  /// down or lifted), due finger_lead_s after now on the player's clock.
  /// Returns the sample as queued, or nothing if the player's queue is full
  /// (or the presenter simulates its finger). Control thread only.
  std::optional<FingerSample> push_finger(double x_mm, bool touching);
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
  std::optional<FrequencyResponse> last_response_;  // of the last map shown (blank() keeps it)
  double next_finger_s_ = 0.0;                      // simulated: next sample's time; external: newest sample's time
  double period_s_ = 0.0;
  std::size_t shown_ = 0;
  bool running_ = false;
};

}  // namespace texel::experiment
