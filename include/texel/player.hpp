// The real-time player: finger positions in, drive values out.
//
// config → prepare → process (docs/contributing.md §1). A PlayerMap is the prepared,
// immutable amplitude map of a whole surface (all regions) on its device
// grid; a Player is built from a PlayerConfig (allocating everything it will
// ever need), then process() turns the finger stream into output samples at a
// fixed rate: the device refresh rate (8,333 Hz for `tpad`) or an audio rate.
//
// Threads. Exactly one control thread calls set_map / push / set_gain /
// set_carrier / collect, and exactly one real-time thread calls process.
// Finger samples and parameter commands reach process() through a
// fixed-capacity SPSC queue (spsc_queue.hpp); a new map arrives through an
// atomic pointer exchange and replaces the old one with a crossfade; the
// old map goes back through a second SPSC queue and is freed by collect() on
// the control thread — never in process().
//
// Finger model. Samples are consumed in time order. At output time t the
// player looks at τ = t + prediction_s: between two known samples the
// position is interpolated linearly; past the newest sample it is
// extrapolated with the smoothed finger velocity for at most
// extrapolate_s (the latency predictor; the public TPaD tablet software
// predicts 20 ms ahead), then held. Off-line rendering simply queues
// samples ahead of time, so the same code interpolates a whole trace.
//
// Map sampling. At audio rates a finger at 100 mm/s moves 0.002 mm per
// sample, less than one map sample (0.0053 mm on `tpad`), so a map is read
// between its grid samples, never stepped from sample to sample.
//
// Band limit ([choice] PlayerConfig::band_limit, on by default;
// docs/player.md §5). A spatial frequency f felt at speed v is
// f·|v| Hz; above the output's Nyquist rate it would alias (a 7.5 dB
// texture at 100 mm/s, 562 Hz, streamed at 439 Hz on a 1 kHz drive), and no
// filter after the sampling can remove what sampling folded down. So the
// player band-limits the texture at the finger before it samples it, at
// the limit L = the display's response limit (below), else 0.45·rate, and
// the finger's speed |v| (from consecutive output samples):
//   - Texel regions are evaluated texel by texel at the finger (the map
//     keeps each texel's frequency, phase and envelope: the value equals the
//     rendered map's at its grid samples), and texel k is faded towards its
//     mean by limit_weight(f_k·|v|, L): whole up to 0.8·L, a raised cosine
//     to 0 at L — the 2-D player's rule. So that a faded texel leaves no step
//     at its edges (a step is broadband and would alias too), the fade
//     reaches into its neighbours: within δ = 5·|v|/L of a texel weighted w_j
//     (5 periods of the limit; at most 32 texels) the weight is at most
//     max(w_j, raised cosine of the distance / δ), so it is continuous.
//   - Anything else (reference textures, maps from files or raw values) is
//     read from a pyramid built when the map is made: level j holds the map
//     with its content cut to 1/2^j of its Nyquist frequency (129-tap
//     Blackman-windowed sinc), stored twice oversampled; the finger reads,
//     cubically and blended between two neighbouring levels, the ones whose
//     content stops under the output's Nyquist frequency at its speed.
//     Trade-off: octave levels are coarse, so such content is whole only up
//     to about a fifth of the limit at worst and fades above it (a Texel
//     region's is whole to 0.8 × the limit).
// Off: the map's samples interpolated linearly, as before (aliases).
//
// Output modes (PlayerConfig::mode):
//   amplitude  a(x) in [0, 1], for friction displays (0 = at rest);
//   vibration  a(x) band-passed: a 2nd-order Butterworth low-pass
//              (lowpass_hz, default 0.4·rate) then a one-pole DC blocker
//              (high-pass at highpass_hz), so the output is zero-mean. Unit
//              gain: a full-range fine texture gives ±0.5 (−6 dBFS), which
//              leaves room for the DC blocker's settling after a touch-down
//              without clipping; clipped to [−1, 1];
//   carrier    a(x)·sin(2π·f_c·t) from a phase accumulator, for displays fed
//              from a signal generator or amplifier.
// Touch and lift fade the output in and out with a raised-cosine ramp of
// touch_ramp_s (no click); a finger beyond the surface counts as lifted.
//
// The display's frequency response (PlayerConfig::response, from the device
// profile; docs/format.md "Frequency response"). [choice] limit: the player
// never drives content the display cannot reproduce: the map value under the
// finger goes through a 2nd-order Butterworth low-pass at the frequency where
// the display's response has fallen by response_limit_db (20 dB: a tenth of
// the amplitude). The player runs in time, so this holds at whatever speed
// the finger moves: a spatial frequency f at speed v is f·v Hz. Within the
// display's pass band the filter costs at most 0.04 dB (first-order display:
// the limit is 10× the corner); beyond it, drive the display would not turn
// into friction is not sent (it would only load the amplifier and the
// resonator). Skipped when the limit is above 0.45·rate (the output rate
// already band-limits more) or the response is flat; off: as before.
// The response travels with the map: a map made for a device
// (PlayerMap::from_document, or a response given to the constructor) carries
// that device's response, and the player respects it in place of
// PlayerConfig::response while the map plays, so one player can show
// documents of different displays (the experiments' Presenter, the C API's
// texel_player_set_surface). process() recomputes the limit filter's
// coefficients (a few sin/cos/pow, no allocation) at the instant it takes
// the new map; the filter keeps its state (limit → limit) or starts settled
// on the value under the finger (none → limit). During that map's crossfade
// the outgoing map is limited by the incoming display's response too — it
// lasts crossfade_s (20 ms) and fades out anyway.
// Pre-emphasis (boosting within the pass band to flatten the display) is not
// done: amplitudes live in [0, 1] with no headroom, and a boost would raise
// the map's steps' overshoot and sensor noise with it.
//
// Lifetime. A Player is small (< 1 KiB: its queues' rings are allocated by
// the constructor, i.e. at prepare) and can live on any stack. Whatever calls
// process() from its own thread — a Backend (sinks.hpp) — is a PlayerDriver
// and holds a PlayerAttachment to the one player it drives, so neither can
// dangle whichever goes first:
//   - the driver goes first (or stops): it stops calling process(), then its
//     attachment detaches; the player carries on and can be driven again;
//   - the player goes first: ~Player asks the attached driver to stop
//     (PlayerDriver::stop_driving joins its thread / stops its stream) and
//     waits for it, then frees its maps; the driver stays usable (stats,
//     start on another player).
// A player has at most one driver (two real-time threads would break the
// SPSC queues): attaching a second throws. Attach, detach and destruction
// all happen on the control thread; the real-time thread never sees the
// attachment, so the handshake puts no lock or atomic on the audio path.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <type_traits>
#include <vector>

#include "texel/device.hpp"
#include "texel/finger.hpp"
#include "texel/grid.hpp"
#include "texel/player_parts.hpp"
#include "texel/spsc_queue.hpp"

namespace texel {

class Surface;
class Texture;
class TexelTexture;
struct Document;

/// An immutable amplitude map on a uniform grid, in device coordinates (mm).
class PlayerMap {
 public:
  /// `values` holds one amplitude in [0, 1] per grid sample; grid.count must
  /// equal values.size() and be >= 1. `response`: the frequency response of
  /// the display the map is for (its DeviceProfile::response); while this map
  /// plays the player respects it in place of PlayerConfig::response (see
  /// above); absent = the config's. Throws InvalidArgument otherwise or for
  /// an invalid response.
  PlayerMap(Grid grid, std::vector<float> values, std::optional<FrequencyResponse> response = std::nullopt);
  /// The whole device map of a surface, all regions (gaps at rest), carrying
  /// `response` (absent: the player's config decides).
  static std::unique_ptr<const PlayerMap> from_surface(const Surface& surface,
                                                       std::optional<FrequencyResponse> response = std::nullopt);
  /// The whole map of a document on its device, carrying the device's
  /// frequency response (doc.device.response): what the experiments'
  /// Presenter, the studio's Feel-it and the C API play. A document of
  /// simultaneous channels (multichannel.hpp) has no one map: InvalidArgument.
  static std::unique_ptr<const PlayerMap> from_document(const Document& doc);
  /// A single texture laid on `grid` (texture coordinates = grid positions).
  static std::unique_ptr<const PlayerMap> from_texture(const Texture& texture, const Grid& grid);

  [[nodiscard]] const Grid& grid() const { return grid_; }
  [[nodiscard]] std::span<const float> values() const { return values_; }
  /// The display's response this map carries, if any (see the constructor).
  [[nodiscard]] const std::optional<FrequencyResponse>& response() const { return response_; }
  /// Linear interpolation between grid samples; positions beyond the ends
  /// take the nearest end value (the caller decides what "off the surface"
  /// means). Real-time safe.
  [[nodiscard]] float sample(double x_mm) const noexcept;
  /// The value at x with content above `limit_cpm` (cycles/mm: the limit in
  /// Hz over the finger's speed) removed — see "Band limit" above. An
  /// infinite limit (a finger at rest) removes nothing: a Texel region gives
  /// the texture's own value at x (the rendered map's at a grid sample), the
  /// rest sample(x). Real-time safe: arithmetic on the map's own arrays.
  [[nodiscard]] double band_limited(double x_mm, double limit_cpm) const noexcept;
  /// How many of the map's regions are evaluated texel by texel.
  [[nodiscard]] std::size_t texel_regions() const noexcept { return lines_.size(); }
  /// Pyramid levels besides the map itself (for content without texels).
  [[nodiscard]] std::size_t pyramid_levels() const noexcept { return levels_.size(); }

  /// At most this many texels (all regions) are kept for evaluation at the
  /// finger (32 bytes each); a surface with more plays its regions from the
  /// pyramid instead.
  static constexpr std::size_t max_texels = std::size_t{1} << 21;
  /// The neighbour fade's reach, in periods of the limit, and its cap in texels.
  static constexpr double fade_reach_periods = 5.0;
  static constexpr int fade_reach_texels = 32;
  /// True if x lies on the surface: [origin, origin + count·spacing).
  [[nodiscard]] bool on_surface(double x_mm) const noexcept;

 private:
  /// One Texel region, texel by texel (what TexelTexture::render computes).
  struct TexelLine {
    struct Texel {
      double frequency;  // f_k, cycles/mm
      double phase;      // φ_k, cycles at the texel's left edge
      double offset;     // e_k·(1 − F/2)
      double gain;       // e_k·F/2
    };
    double start_mm = 0.0, end_mm = 0.0;  // the region on the device: [start, end)
    double texel_mm = 0.0;                // L
    double textured_end_mm = 0.0;         // region coordinates: beyond it, rest
    std::vector<Texel> texels;
    [[nodiscard]] double value(double local_mm, double limit_cpm) const noexcept;
  };
  PlayerMap(Grid grid, std::vector<float> values, std::optional<FrequencyResponse> response, bool pyramid);
  static TexelLine texel_line(const TexelTexture& texture, double start_mm, double end_mm);
  void build_pyramid();
  [[nodiscard]] double cubic_level(std::size_t level, double x_mm) const noexcept;
  [[nodiscard]] double pyramid_value(double x_mm, double limit_cpm) const noexcept;

  Grid grid_;
  std::vector<float> values_;
  std::optional<FrequencyResponse> response_;
  double inv_spacing_ = 0.0;
  std::vector<TexelLine> lines_;            // Texel regions, ascending
  std::vector<std::vector<float>> levels_;  // pyramid levels 1, 2, …: spacing 2^j × the grid's
};

enum class OutputMode { amplitude, vibration, carrier };
/// How the player respects the display's frequency response (see above). [choice] limit.
enum class ResponseHandling { limit, off };
std::string_view to_string(ResponseHandling h);
ResponseHandling parse_response_handling(std::string_view text, std::string_view field = "response_handling");
/// Whether the player band-limits the texture at the finger's speed (see "Band limit"). [choice] on.
enum class BandLimit { on, off };
std::string_view to_string(BandLimit b);
BandLimit parse_band_limit(std::string_view text, std::string_view field = "band_limit");
std::string_view to_string(OutputMode m);
OutputMode parse_output_mode(std::string_view text, std::string_view field = "output");

struct PlayerConfig {
  double rate_hz = 48000.0;  ///< output rate (s⁻¹), 100 … 384000; tpad: 8333
  OutputMode mode = OutputMode::amplitude;
  double gain = 1.0;                   ///< output gain, 0 … 1 (changes are ramped over one block)
  double carrier_hz = 250.0;           ///< carrier mode: carrier frequency (Hz), 0 … rate/2
  double prediction_s = 0.0;           ///< latency compensation: look-ahead (s), 0 … 0.1 (TPaD tablet: 0.02)
  double extrapolate_s = 0.03;         ///< longest extrapolation past the newest sample (s), >= prediction_s
  double velocity_smoothing_s = 0.01;  ///< time constant of the velocity estimate (s), > 0
  double touch_ramp_s = 0.005;         ///< fade in on touch / out on lift (s), 0.0005 … 1
  double crossfade_s = 0.02;           ///< crossfade when a new map is swapped in (s), 0.0005 … 1
  double highpass_hz = 20.0;           ///< vibration: DC-blocker corner (Hz), 0.1 … rate/4
  double lowpass_hz = 0.0;             ///< vibration: low-pass corner (Hz); 0 = 0.4·rate; at most 0.45·rate
  /// Finger samples and commands that can wait for process(): a power of two,
  /// 16 … 1,048,576 (default 4096: 4 s of a 1 kHz position sensor queued
  /// ahead). The ring (40 B per event) is allocated at prepare.
  std::size_t event_capacity = 4096;
  /// The display's frequency response (DeviceProfile::response); flat (the
  /// default) promises nothing, so nothing is limited.
  FrequencyResponse response{};
  ResponseHandling response_handling = ResponseHandling::limit;  ///< [choice] limit (see above)
  double response_limit_db = 20.0;       ///< limit: attenuation (dB) at which the display no longer reproduces, 3 … 60
  BandLimit band_limit = BandLimit::on;  ///< [choice] on: no content above the limit at the finger's speed (see above)
};
/// The low-pass corner (Hz) the player applies for `config`, or 0 for none.
double response_limit_hz(const PlayerConfig& config);
/// The same for a map that carries `response` (PlayerMap::response) under
/// `config`'s handling, limit and rate. Real-time safe (arithmetic only).
double response_limit_hz(const PlayerConfig& config, const FrequencyResponse& response) noexcept;
/// Throws InvalidArgument naming the field, the value and the allowed range.
void validate(const PlayerConfig& config);

inline constexpr OptionChoice output_modes[] = {{"amplitude", static_cast<int>(OutputMode::amplitude)},
                                                {"vibration", static_cast<int>(OutputMode::vibration)},
                                                {"carrier", static_cast<int>(OutputMode::carrier)}};
inline constexpr OptionChoice response_handlings[] = {{"limit", static_cast<int>(ResponseHandling::limit)},
                                                      {"off", static_cast<int>(ResponseHandling::off)}};
inline constexpr OptionChoice band_limits[] = {{"on", static_cast<int>(BandLimit::on)},
                                               {"off", static_cast<int>(BandLimit::off)}};

/// The player's options an embedder sets (C's texel_player_config), described
/// once (texel/option_spec.hpp) with PlayerConfig{}'s defaults: amplitude
/// out, as a friction display takes it. The rest of PlayerConfig (filters,
/// ramps, queue) keeps its defaults at every front door.
template <class Config, class Visit>
requires std::is_same_v<std::remove_const_t<Config>, PlayerConfig>
void visit_options(Config& c, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(c.rate_hz, OptionSpec{"rate_hz", "rate", "Output rate (Hz); 8333 for the tpad's refresh rate", 100, 384000});
  visit(c.mode, OptionSpec{"output", "output", "amplitude (friction map value), vibration (zero-mean, band-limited) or carrier",
                           -inf, inf, false, false, output_modes});
  visit(c.gain, OptionSpec{"gain", "gain", "Output gain, 0 … 1", 0, 1});
  visit(c.carrier_hz, OptionSpec{"carrier_hz", "carrier", "Carrier frequency of the carrier output (Hz), up to rate/2", 0});
  visit(c.prediction_s, OptionSpec{"prediction_s", "prediction",
                                   "Latency compensation: predict the finger this far ahead (s; TPaD tablet: "
                                   "0.02)",
                                   0, 0.1});
  visit(c.response_handling,
        OptionSpec{"response", "response",
                   "The display's frequency response (device profile): limit (never drive what the display attenuates "
                   "by response_limit_db or more) or off",
                   -inf, inf, false, false, response_handlings});
  visit(c.response_limit_db, OptionSpec{"response_limit_db", "response-limit",
                                        "limit: the display's attenuation (dB) where driving stops, 3 … 60", 3, 60});
}

/// A texture played under a simulated finger as the front doors offer it:
/// `texel swipe` and `texel play` (their finger and output flags), Python's
/// swipe(); described once (visit_options below). A swipe renders what a
/// finger feels, so its output is vibration where the embedded player's
/// (PlayerConfig) is amplitude. `texel play` plays 5 s (play_options()).
struct SwipeOptions {
  MmPerSecond speed{100.0};                             ///< cruising speed, > 0
  SwipePattern pattern = SwipePattern::constant;        ///< SwipeConfig::pattern
  Millimetres start{0.0};                               ///< where the finger lands
  Millimetres extent{0.0};                              ///< travel of one stroke; 0 = to the end of the surface
  Seconds turn{0.1};                                    ///< back-and-forth: time to stop and turn
  Seconds duration{2.0};                                ///< length of the output (a recorded trace: the trace's)
  Hertz rate{48000.0};                                  ///< output rate (a serial display: its link's)
  OutputMode output = OutputMode::vibration;            ///< PlayerConfig::mode
  Hertz carrier{250.0};                                 ///< PlayerConfig::carrier_hz
  Seconds prediction{0.0};                              ///< PlayerConfig::prediction_s
  double gain = 1.0;                                    ///< PlayerConfig::gain
  ResponseHandling response = ResponseHandling::limit;  ///< PlayerConfig::response_handling
  BandLimit band_limit = BandLimit::on;                 ///< PlayerConfig::band_limit
};
/// `texel play`'s: SwipeOptions with a 5 s simulated finger.
SwipeOptions play_options();
/// The player configuration `o` describes (the rest PlayerConfig{}'s), for a
/// display with `response`; validated (InvalidArgument naming the field).
PlayerConfig player_config(const SwipeOptions& o, const FrequencyResponse& response);
/// The simulated swipe `o` describes over a surface `surface` long, sampled
/// at 1 kHz (simulate_swipe validates it, naming the field).
SwipeConfig swipe_config(const SwipeOptions& o, Millimetres surface);

template <class Options, class Visit>
requires std::is_same_v<std::remove_const_t<Options>, SwipeOptions>
void visit_options(Options& o, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(o.speed, OptionSpec{"speed_mm_s", "speed", "Swipe speed (mm/s)", 0, inf, true});
  visit(o.pattern, OptionSpec{"pattern", "pattern", "Simulated swipe: constant (repeated one-way strokes) or back-and-forth",
                              -inf, inf, false, false, swipe_patterns});
  visit(o.start, OptionSpec{"start_mm", "start", "Where the simulated finger lands (mm)"});
  visit(o.extent, OptionSpec{"extent_mm", "extent", "Travel of one stroke (mm); 0 = to the end of the surface", 0});
  visit(o.turn, OptionSpec{"turn_s", "turn", "Back-and-forth: time to stop and turn (s)", 0, 10});
  visit(o.duration, OptionSpec{"duration_s", "duration", "Length (s); a recorded trace: the trace's", 0, 86400, true});
  visit(o.rate, OptionSpec{"rate_hz", "rate",
                           "Output rate (Hz); 8333 for the tpad's refresh rate; play to a serial display: its link's "
                           "(1000)",
                           100, 384000});
  visit(o.output, OptionSpec{"output", "output", "amplitude (friction map value), vibration (zero-mean, band-limited) or carrier",
                             -inf, inf, false, false, output_modes});
  visit(o.carrier, OptionSpec{"carrier_hz", "carrier", "Carrier frequency of the carrier output (Hz), up to rate/2", 0});
  visit(o.prediction, OptionSpec{"prediction_s", "prediction",
                                 "Latency compensation: predict the finger this far ahead (s; TPaD tablet: 0.02)", 0, 0.1});
  visit(o.gain, OptionSpec{"gain", "gain", "Output gain, 0 … 1", 0, 1});
  visit(o.response, OptionSpec{"response", "response",
                               "The display's frequency response (device profile): limit (never drive what the display "
                               "attenuates by 20 dB or more) or off",
                               -inf, inf, false, false, response_handlings});
  visit(o.band_limit, OptionSpec{"band_limit", "band-limit",
                                 "on: no content above the drive's limit at the finger's speed (texels faded, "
                                 "docs/player.md); off: the map as sampled (aliases)",
                                 -inf, inf, false, false, band_limits});
}

/// A command for process(): a finger sample or a parameter change.
using PlayerEvent = player_parts::Event<FingerSample>;
/// The coordinates a FingerTrack follows (player_parts.hpp).
inline std::array<double, 1> coords(const FingerSample& s) noexcept { return {s.x_mm}; }

/// What process() reports for one block.
struct BlockInfo {
  float peak = 0.0f;           ///< largest |output| in the block
  double position_mm = 0.0;    ///< finger position at the block's end (after prediction); 2-D: x
  double position_y_mm = 0.0;  ///< 2-D players: y at the block's end
  bool touching = false;       ///< finger down at the block's end
  bool crossfading = false;
};

class PlayerBase;

/// Whatever calls PlayerBase::process() from its own real-time thread (the
/// backends of sinks.hpp). See "Lifetime" above.
class PlayerDriver {
 public:
  /// Control thread, called by a player's destructor while this driver is
  /// still attached: stop calling process() and return only when no call is
  /// in progress (join the thread, stop the stream), then detach.
  virtual void stop_driving() noexcept = 0;

 protected:
  PlayerDriver() = default;
  PlayerDriver(const PlayerDriver&) = default;
  PlayerDriver& operator=(const PlayerDriver&) = default;
  ~PlayerDriver() = default;
};

/// The RAII link between a driver and the one player it drives: while it is
/// attached, the player knows whom to stop before it goes away. A member of
/// the driver; control thread only; neither copyable nor movable (the player
/// holds its address).
class PlayerAttachment {
 public:
  explicit PlayerAttachment(PlayerDriver& driver) noexcept : driver_(&driver) {}
  ~PlayerAttachment() { detach(); }
  PlayerAttachment(const PlayerAttachment&) = delete;
  PlayerAttachment& operator=(const PlayerAttachment&) = delete;

  /// Before the driver's first process() call. Detaches from a previous
  /// player first. Throws InvalidArgument if another driver is attached to
  /// `player` (one real-time thread per player).
  void attach(PlayerBase& player);
  /// After the driver's last process() call has returned. Safe to call twice.
  void detach() noexcept;
  /// The player driven, or null.
  [[nodiscard]] PlayerBase* player() const noexcept { return player_; }

 private:
  friend class PlayerBase;
  PlayerDriver* driver_;
  PlayerBase* player_ = nullptr;
};

/// What a driver drives: the 1-D Player or the 2-D Player2D (player2d.hpp).
class PlayerBase {
 public:
  virtual ~PlayerBase() = default;
  PlayerBase(const PlayerBase&) = delete;
  PlayerBase& operator=(const PlayerBase&) = delete;

  /// Real-time thread: fills `out` with the next out.size() samples and, if
  /// `position_mm` is not empty (same size as out), the finger position used
  /// for each (2-D: x). Real-time safe (see Player::process).
  virtual BlockInfo process(std::span<float> out, std::span<float> position_mm = {}) noexcept = 0;
  /// Control thread: frees maps process() has retired. Returns how many.
  virtual std::size_t collect() = 0;

  /// True while a driver (a started Backend) is attached. Control thread.
  [[nodiscard]] bool attached() const { return attachment_ != nullptr; }
  /// Output samples produced so far (any thread).
  [[nodiscard]] std::uint64_t samples() const { return samples_done_.load(std::memory_order_relaxed); }
  [[nodiscard]] double time_s() const { return static_cast<double>(samples()) / rate_hz_; }

 protected:
  explicit PlayerBase(double rate_hz) : rate_hz_(rate_hz) {}
  /// Derived destructors call this first: an attached driver may be inside
  /// process() right now; it is stopped and waited for before anything is freed.
  void stop_driver() noexcept;
  void publish_samples(std::uint64_t n) noexcept { samples_done_.store(n, std::memory_order_relaxed); }

 private:
  friend class PlayerAttachment;
  PlayerAttachment* attachment_ = nullptr;  // the driver's link; control thread only
  std::atomic<std::uint64_t> samples_done_{0};
  double rate_hz_;
};

class Player final : public PlayerBase {
 public:
  static constexpr std::size_t retire_capacity = player_parts::MapExchange<PlayerMap>::retire_capacity;

  /// prepare: validates `config` and allocates all state (the event and
  /// retire rings included); `map` may be null (silence until set_map).
  explicit Player(const PlayerConfig& config, std::unique_ptr<const PlayerMap> map = nullptr);
  /// Stops an attached driver first (see "Lifetime"), then frees every map.
  /// A real-time thread that is not an attached driver must have stopped.
  ~Player() override;

  [[nodiscard]] const PlayerConfig& config() const { return config_; }
  /// Capacity of the event queue (config().event_capacity).
  [[nodiscard]] std::size_t event_capacity() const { return events_.capacity(); }

  // -------------------------------------------------------- control thread
  /// Swaps in a new map; process() crossfades to it. If a previous map was
  /// still waiting (never seen by process) it is freed here. Also collect()s.
  void set_map(std::unique_ptr<const PlayerMap> map) { maps_.set(std::move(map)); }
  /// Queues a finger sample (time-ordered); false if the queue is full.
  bool push(const FingerSample& s) { return events_.try_push(PlayerEvent{PlayerEvent::Kind::finger, s, 0.0}); }
  /// Queues a gain change (clamped to [0, 1], ramped over one block).
  bool set_gain(double gain);
  /// Queues a carrier-frequency change (clamped to [0, rate/2]).
  bool set_carrier(double hz);
  /// Frees maps process() has retired. Returns how many.
  std::size_t collect() override { return maps_.collect(); }
  /// Free slots in the event queue (approximate while process() runs).
  [[nodiscard]] std::size_t event_space() const { return events_.capacity() - events_.size(); }

  // ------------------------------------------------------- real-time thread
  /// Fills `out` with the next out.size() samples and, if `position_mm` is
  /// not empty (same size as out), the finger position used for each.
  ///
  /// Real-time safe: never allocates, frees, locks, logs, throws or does
  /// I/O; bounded work per sample. Out-of-range parameters were clamped when
  /// queued.
  BlockInfo process(std::span<float> out, std::span<float> position_mm = {}) noexcept override;

 private:
  void use_response_of(const PlayerMap* map) noexcept;

  PlayerConfig config_;
  SpscQueue<PlayerEvent> events_;
  player_parts::MapExchange<PlayerMap> maps_;
  // Real-time state (touched only by process()).
  player_parts::FingerTrack<FingerSample, 1> finger_;
  player_parts::OutputStage stage_;
  std::uint64_t n_ = 0;
  double last_x_ = 0.0;  // the previous output sample's position (speed)
  bool have_x_ = false;  // … and whether the finger touched there
};

/// Off-line rendering of a whole trace through a Player: queues the trace
/// ahead of time (so every position is interpolated between known samples),
/// processes `frames` samples in `block`-sized blocks and returns them;
/// `positions`, if given, receives the position used for each sample.
std::vector<float> render_trace(const PlayerMap& map, const PlayerConfig& config, std::span<const FingerSample> trace,
                                std::size_t frames, std::vector<float>* positions = nullptr, std::size_t block = 64);

/// Magnitude spectrum of a signal (Hann window, zero-padded to a power of
/// two): bin k at k·rate/n Hz. Used by --plot and the tests.
struct SignalSpectrum {
  std::vector<double> frequency_hz;
  std::vector<double> magnitude;
  [[nodiscard]] double peak_hz(double min_hz = 0.0) const;
};
SignalSpectrum signal_spectrum(std::span<const float> signal, double rate_hz);

}  // namespace texel
