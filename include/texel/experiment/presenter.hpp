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
// The 2-D display (FingerSource::display, `texel experiment run --finger
// serial:PATH`): the participant strokes a 2-D surface display themselves.
// Each interval of an oddity-2d trial plays as a Player2D map (path-indexed,
// or the static field's friction bitmap: Stimulus::surface) under the live
// finger the display reports (serial protocol 1.1 FINGER reports, read on
// their own thread and placed on the player's clock by ReportTimeline). The
// same reports are summarised per interval (strokes.hpp): strokes, mean
// direction, speed and path, and whether the direction is the one asked for
// (StrokeRules). A display without a finger sensor is refused at
// construction (InvalidArgument, one line).
//
// Presentation modes (finger_trace.hpp), chosen per display from its HELLO
// and whether it senses the finger (PresenterOptions::mode, [choice] the
// display's own):
//   display-plays  a serial display with map slots and a finger sensor:
//                  prepare() uploads the trial's stimuli (texel render's
//                  exact u16 samples: Surface::render_native) into its slots
//                  before onset, show() SELECTs one, blank() SELECTs none. The
//                  display plays from its own sensed position at its own
//                  rate; the host only reads its FINGER reports (pump()). With
//                  fewer slots than stimuli a switch to a stimulus not held
//                  uploads it over the one least recently felt
//                  (upload_counts() says how often and how long).
//   host-streams   a serial display with a sensor but no slots (or asked so),
//                  or a pointer pushed from outside (FingerSource::external):
//                  the player computes the drive from the reported finger and
//                  streams it at 1 kHz (serial) or the sound card's rate;
//                  check() says what that rate cannot carry.
//   passive        no finger (audio actuators, null, a display without a
//                  sensor): the simulated sweep above.
// A display that cannot do the mode asked is refused at construction
// (InvalidArgument, one line). Every trial's finger trace is kept from
// prepare() to take_trace() (display reports on the display's clock, or the
// simulated finger), for the swipe measures.
//
// Multi-actuator displays (docs/rendering.md, docs/experiments.md
// "Presentation"): PresenterOptions::channels = N > 1 opens the backend
// (null, audio) with N channels and plays through a ChannelPlayer, one Player
// per actuator. show() prepares each channel's map of the document
// (prepare_channels: sequential, the one chain at every actuator's offset or
// on one actuator; simultaneous, one chain per actuator), each carrying its
// actuator's response, and swaps them in together (each channel crossfades;
// a channel at rest gets silence); blank() silences every channel. Every
// finger (simulated, external, a separate sensor) drives every channel,
// shifted by each actuator's offset (the document's device's). Finger
// samples are queued ahead of the player (the simulated sweep 50 ms, an
// external finger finger_lead_s) with the offsets in force when pushed, so
// when a show brings other offsets (the session's first stimulus, or a
// document of another device) its maps wait in pump() until the samples
// queued before it have played: that stimulus starts up to 50 ms later,
// and its maps never see the finger jump by an offset. A
// one-channel document (a device without actuators) plays on every channel
// at offset 0, as a sequential document does. Refused in one line
// (InvalidArgument): a document whose device has other than 1 or N channels
// (at show(), check() and prepare(), so before its trial's onset); a serial
// display or a 2-D display with N > 1 (the serial protocol drives one
// plate). The front ends take N from the protocol's device
// (presentation_channels).
//
// At rest on every exit: stop() (and the destructor, so an exception
// unwinding past the presenter) SELECTs none on a serial display after the
// stream has stopped, so the plate is never left driven.
//
// Trade-off: one control thread, no callback into the engine; the real-time
// side is the player's (no allocation, locks or I/O).
#pragma once

#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "texel/experiment/finger_trace.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/strokes.hpp"
#include "texel/sinks.hpp"

namespace texel {
class ChannelPlayer;
}  // namespace texel

namespace texel::experiment {

/// Where finger positions come from (see the banner): simulated, pushed from
/// outside (the studio's strip), a 2-D display's own sensor, or a 1-D
/// sensor on a link of its own (`sensor`: a display or touch strip that
/// reports the finger while the backend — a sound card's actuators, or a
/// display without a sensor — plays; always host-streams).
enum class FingerSource { simulated, external, display, sensor };

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
  /// FingerSource::display: the display that reports the finger, "serial:PATH"
  /// (the backend's own path, or another display's); FingerSource::sensor:
  /// the 1-D sensor's "serial:PATH" (never the backend's own: a display with
  /// a sensor is its own finger).
  std::string finger_display;
  std::uint32_t report_interval_us = 1000;  ///< FINGER report interval asked of the display
  int baud = 921600;
  /// FingerSource::display: what a stroke must be (strokes.hpp).
  StrokeRules stroke_rules;
  /// How stimuli reach the finger (see the banner). [choice] nullopt: the
  /// display's own — display-plays with slots and a sensor, host-streams with
  /// a sensor only or an external finger, passive without a finger.
  std::optional<PresentationMode> mode;
  /// Output channels, one per actuator of a multi-actuator display
  /// (DeviceProfile::actuators), 1 … 64 [1]. N > 1: null and audio only; a
  /// stimulus's device must have N actuators or none (see the banner). The
  /// front ends set it from the protocol's device: presentation_channels().
  std::size_t channels = 1;
};

/// The output channels a session of `protocol` plays on: its device's
/// actuators (DeviceProfile::channels(): 1 for a device without). What
/// `texel experiment run`, the studio and Python put in
/// PresenterOptions::channels. Throws InvalidArgument for an unknown device.
std::size_t presentation_channels(const Protocol& protocol);
/// The same for a device: a built-in name, a NAME.json on TEXEL_DEVICE_PATH
/// or a profile's path (load_device).
std::size_t presentation_channels(std::string_view device);

class Presenter {
 public:
  /// Opens and starts the backend (throws InvalidArgument / IoError naming it).
  explicit Presenter(const PresenterOptions& options);
  /// Plays through `backend` instead of opening options.backend: an output
  /// the caller made (an application's own sound I/O, a test's recording
  /// backend), driven like a sound card (passive, or external/sensor
  /// fingers). Throws InvalidArgument unless backend->channels() equals
  /// options.channels, or for a serial display's backend (give it by name).
  Presenter(const PresenterOptions& options, std::unique_ptr<Backend> backend);
  ~Presenter();
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  /// Plays the texture document (a Texel document as JSON text). Not on a
  /// 2-D display (InvalidArgument): it plays stimuli, show(const Stimulus&).
  void show(const std::string& document_json);
  /// Plays the question's stimulus i: on a 2-D display its surface
  /// (Question::surfaces[i]; the strokes are this interval's until another
  /// is shown or blank()), else its document. A 2-D display refuses a
  /// question without surfaces (InvalidArgument).
  void show(const Question& question, std::size_t i);
  /// Gets the question ready before its onset: a 2-D display's maps are
  /// rendered (switching then costs a copy; waits for a bitmap the preload
  /// is rendering rather than rendering it again) and its strokes cleared;
  /// display-plays uploads the stimuli into the display's slots (as many as
  /// it holds); otherwise (passive, host-streams) every stimulus's maps are
  /// prepared into the cache, so a switch costs a copy and a stimulus of
  /// another channel count is refused (InvalidArgument) before onset.
  /// Starts the trial's finger trace (take_trace()).
  void prepare(const Question& question);
  /// The finger trace since prepare() (empty on a 2-D display, whose strokes
  /// are strokes()); recording stops until the next prepare().
  FingerTrace take_trace();
  /// The mode in force.
  [[nodiscard]] PresentationMode mode() const { return mode_; }
  /// What the presentation cannot do for `first` (the session's first
  /// question), as lines for the experimenter, before the first trial:
  /// host-streams at a rate that cannot carry the stimuli's finest texels at
  /// a 100 mm/s swipe (with the figures), display-plays with fewer slots than
  /// stimuli (what a switch costs). Throws InvalidArgument when a stimulus's
  /// map is larger than the display holds, or its device has other than 1
  /// or channels() actuators.
  [[nodiscard]] std::vector<std::string> check(const Question& first) const;
  /// display-plays: maps uploaded, how many of them at a switch (the
  /// participant waited), and the time spent uploading (s).
  struct UploadCounts {
    int uploads = 0, at_switch = 0;
    double seconds = 0.0;
  };
  [[nodiscard]] UploadCounts upload_counts() const;
  /// Starts rendering, on a background thread at a lower priority, every
  /// friction bitmap a session of `protocol` with `context` will show (the
  /// questions the session asks, in order, up to the presenter's cache of
  /// eight), so that a trial's prepare() finds its maps ready. Call it once
  /// the session is open, before the instructions; stop() ends it. No-op
  /// without a 2-D display or when already started.
  void preload(const Protocol& protocol, const SessionContext& context);
  /// Whether the preload has finished (every bitmap it could keep rendered).
  [[nodiscard]] bool preloaded() const;
  /// Friction bitmaps rendered by the preload, and by prepare()/show() for
  /// a trial (each one a participant waited for).
  struct BitmapCounts {
    int preloaded = 0, at_trial = 0;
  };
  [[nodiscard]] BitmapCounts bitmap_counts() const;
  /// Whether the participant strokes a 2-D display (FingerSource::display).
  [[nodiscard]] bool two_d() const { return display_ != nullptr; }
  /// The strokes of the question's intervals since prepare(), one entry per
  /// stimulus in the question's order (an interval never stroked has 0
  /// strokes and does not comply). Empty without a 2-D display.
  [[nodiscard]] std::vector<IntervalStrokes> strokes(const Question& question) const;
  /// Plays a map prepared by the caller (PlayerMap::from_document, which
  /// carries the device's response), so a front end shared by several
  /// threads can render outside its lock. With several channels it plays
  /// on every channel at offset 0 (a copy each).
  void show(std::unique_ptr<const PlayerMap> map);
  /// Output channels (PresenterOptions::channels).
  [[nodiscard]] std::size_t channels() const { return options_.channels; }
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
  /// Stops the backend and puts a serial display at rest (SELECT none);
  /// statistics stay readable. Safe to call twice; never throws.
  void stop();

  [[nodiscard]] BackendStats stats();
  [[nodiscard]] std::string describe() const;
  /// The backend's block period (s), for reporting worst-block fractions.
  [[nodiscard]] double block_period_s() const;
  /// Maps shown so far.
  [[nodiscard]] std::size_t shown() const { return shown_; }
  /// An error the backend reported (e.g. the serial link dropped); empty if none.
  [[nodiscard]] std::string error() const;
  /// 2-D display: finger reports taken, lost on the link, and not queued (the player's queue was full).
  struct FingerCounts {
    std::uint64_t reports = 0, lost = 0, dropped = 0;
  };
  [[nodiscard]] FingerCounts finger_counts() const;

 private:
  struct Display2D;
  std::unique_ptr<Display2D> display_;  // FingerSource::display only
  struct Display1D;
  std::unique_ptr<Display1D> display1d_;  // a 1-D serial display in display-plays or host-streams
  PresentationMode mode_ = PresentationMode::passive;
  // The simulated finger's trace (passive), recorded between prepare() and take_trace().
  bool recording_ = false;
  std::vector<FingerSample> simulated_trace_;
  // A stimulus prepared for show(): one map per channel (one on a
  // one-channel presenter) and, with several, the actuators' offsets.
  struct Prepared {
    std::vector<std::unique_ptr<const PlayerMap>> maps;
    std::vector<Millimetres> offsets;
  };
  static constexpr std::size_t cache_size = 8;
  std::list<std::pair<std::string, Prepared>> cache_;  // most recent first
  PresenterOptions options_;
  std::unique_ptr<Player> player_;        // one channel
  std::unique_ptr<ChannelPlayer> multi_;  // channels > 1
  std::unique_ptr<Backend> backend_;
  std::optional<FrequencyResponse> last_response_;                   // of the last map shown (blank() keeps it)
  std::vector<std::optional<FrequencyResponse>> channel_responses_;  // channels > 1: of each channel's last map
  // channels > 1: maps waiting (until the player's clock reaches
  // deferred_until_s_) for the finger samples queued with the previous
  // actuators' offsets to play out; swapped in by pump().
  std::vector<std::unique_ptr<const PlayerMap>> deferred_maps_;
  double deferred_until_s_ = 0.0;
  double next_finger_s_ = 0.0;  // simulated: next sample's time; external: newest sample's time
  double period_s_ = 0.0;
  double rate_hz_ = 0.0;  // the player's output rate (Hz)
  std::size_t shown_ = 0;
  bool running_ = false;
  PlayerBase& output();                   // player_ or multi_
  bool push(const FingerSample& sample);  // to every channel
  Prepared prepare_stimulus(const std::string& document_json) const;
  const Prepared& cached(const std::string& document_json);  // prepared once, most recent first
  void play(const Prepared& prepared);
  void swap_deferred();
  void choose_mode(const BackendChoice& choice);
  void open_sensor(const BackendChoice& choice);  // FingerSource::sensor
};

}  // namespace texel::experiment
