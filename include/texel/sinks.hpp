// Where the player's output goes: files (WAV through libsndfile, CSV), a
// sound card (PortAudio), a `null` backend that runs the same real-time loop
// without hardware (CI has no sound card), and a serial-attached friction
// display (serial_link.hpp).
//
// A Backend owns the real-time thread that calls Player::process: the
// PortAudio callback, a paced thread for `null`, or the streaming thread for
// serial. Statistics are published through relaxed atomics (real-time safe)
// for a level meter on the control thread.
//
// Ownership rule (player.hpp, "Lifetime"): start(player) attaches the
// backend to the player, stop() or the backend's destructor detaches it. The
// two may be destroyed in either order: a backend destroyed first stops its
// thread; a player destroyed first stops the backend before freeing anything.
// A player takes one started backend at a time.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/player.hpp"

namespace texel {

class SerialLink;
struct NativeMap;

enum class WavEncoding { pcm16, pcm24, float32 };

/// Writes a mono WAV atomically (temporary + rename). Samples are clipped to
/// [−1, 1] by the PCM encodings. Throws IoError naming the path.
void write_wav(const std::string& path, std::span<const float> samples, double rate_hz,
               WavEncoding encoding = WavEncoding::pcm16);
/// The same with `channels` (1 … 64) interleaved: samples[i·channels + c] is
/// channel c's frame i (a WAV file's own layout).
void write_wav(const std::string& path, std::span<const float> samples, std::size_t channels, double rate_hz,
               WavEncoding encoding = WavEncoding::pcm16);
// WAV files are read by the one signal loader's audio reader
// (texel::read_recording, texel/signal.hpp).

/// "time_s,position_mm,output" with one row per output sample.
std::string signal_csv(double rate_hz, std::span<const float> positions_mm, std::span<const float> output);
/// "time_s,x_mm,y_mm,output" (2-D players).
std::string signal_csv(double rate_hz, std::span<const float> x_mm, std::span<const float> y_mm, std::span<const float> output);

/// Live statistics of a running backend.
struct BackendStats {
  std::uint64_t blocks = 0;
  double worst_block_s = 0.0;   ///< longest process() call
  double total_block_s = 0.0;   ///< sum of process() calls
  float peak = 0.0f;            ///< peak |output| since the last take_peak()
  std::uint64_t underruns = 0;  ///< sound card or pacing deadlines missed
  double position_mm = 0.0;
  bool touching = false;
};

class Backend : private PlayerDriver {
 public:
  virtual ~Backend() = default;
  Backend(const Backend&) = delete;
  Backend& operator=(const Backend&) = delete;
  /// Attaches to `player` and starts calling player.process() on the
  /// backend's real-time thread; stops a previous run first. Throws
  /// InvalidArgument if another backend drives `player`, IoError if the
  /// device cannot start.
  void start(PlayerBase& player);
  /// Stops (joins the thread, stops the stream) and detaches; safe to call
  /// twice, and called by ~Player if the player goes first.
  void stop() noexcept;
  /// The player being driven, or null (stopped, or its player went away).
  [[nodiscard]] const PlayerBase* player() const noexcept { return attachment_.player(); }
  /// A one-line description ("null 48000 Hz, 64 frames").
  [[nodiscard]] virtual std::string describe() const = 0;
  /// Output channels the backend was opened with: start() drives only a
  /// player of as many (1: Player, Player2D; N: a ChannelPlayer of N,
  /// texel/multichannel_player.hpp, whose blocks are N channels interleaved).
  [[nodiscard]] virtual std::size_t channels() const noexcept { return 1; }
  /// How the real-time thread is scheduled, once started: "SCHED_FIFO
  /// priority 70 (real-time)", "SCHED_OTHER (real-time not permitted: ...)",
  /// or what the sound system chose ("set by PortAudio").
  [[nodiscard]] virtual std::string scheduling() const { return "set by the sound system"; }
  /// An error the real-time side met (e.g. the serial link dropped); empty if none.
  [[nodiscard]] virtual std::string error() const { return {}; }
  /// A serial display's link (null for the other backends): the same
  /// display's finger reports are read through it (SerialLink::read_reports).
  [[nodiscard]] virtual SerialLink* serial_link() noexcept { return nullptr; }

  /// Snapshot of the statistics; resets the peak.
  BackendStats stats();

 protected:
  Backend() : attachment_(*this) {}
  /// Implementations: begin calling player.process(); `player` outlives the
  /// run (until do_stop() returns).
  virtual void do_start(PlayerBase& player) = 0;
  /// Implementations: return only once no process() call is running or can
  /// start; idempotent. Derived destructors call stop().
  virtual void do_stop() noexcept = 0;
  /// Called by implementations after each block (relaxed atomics only).
  void record(const BlockInfo& info, double seconds) noexcept;
  void record_underrun() noexcept { underruns_.fetch_add(1, std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> blocks_{0};
  std::atomic<std::uint64_t> worst_ns_{0};
  std::atomic<std::uint64_t> total_ns_{0};
  std::atomic<float> peak_{0.0f};
  std::atomic<std::uint64_t> underruns_{0};
  std::atomic<double> position_{0.0};
  std::atomic<bool> touching_{false};
  void stop_driving() noexcept override { stop(); }
  PlayerAttachment attachment_;
};

/// Runs the player in real time with no output device: a thread wakes every
/// block period and processes one block into a scratch buffer (of `channels`
/// interleaved, 1 … 64).
std::unique_ptr<Backend> make_null_backend(double rate_hz, std::size_t block_frames, std::size_t channels = 1);

struct AudioOptions {
  std::string device;  ///< PortAudio device index or name substring; empty = default output
  double rate_hz = 48000.0;
  std::size_t block_frames = 64;  ///< frames per buffer
  double latency_s = 0.0;         ///< suggested latency; 0 = the device's low default
  /// Output channels, 1 … 64 (at most the device's): one per actuator of a
  /// ChannelPlayer, interleaved as PortAudio takes them.
  std::size_t channels = 1;
};
/// A sound-card output through PortAudio. Throws IoError if PortAudio or the
/// device cannot be opened (naming the device and listing the outputs).
std::unique_ptr<Backend> make_audio_backend(const AudioOptions& options);
/// Names of PortAudio's output devices, "index: name (host API, channels)".
std::vector<std::string> audio_output_devices();

enum class SerialStream { position, drive };
struct SerialOptions {
  std::string path;
  int baud = 921600;
  double rate_hz = 1000.0;  ///< frames streamed per second; at most the display's refresh rate (lowered to it)
  SerialStream stream = SerialStream::position;
  /// Position stream: the exact map to upload (native_map(doc): `texel
  /// render`'s bytes). Absent: the PlayerMap's float32 values.
  std::shared_ptr<const NativeMap> map;
};
/// A serial friction display: the constructor says HELLO, and (position
/// stream) uploads options.map or `map` to slot 0 within the display's
/// announced limits and selects it; start() streams the player's finger
/// position (or its output as drive values) at options.rate_hz. Every
/// stop() — and the destructor — puts the display at rest (DRIVE 0, SELECT
/// none: SerialLink::rest) once streaming has ended; a later start()
/// selects the map again. Link failures end streaming and are reported by
/// error(). Throws IoError / SerialError from the set-up.
std::unique_ptr<Backend> make_serial_backend(const SerialOptions& options, const PlayerMap& map);

/// The output a backend name selects. Every front door (the CLI's
/// --backend, the experiment presenter) spells it the same way: "null",
/// "audio" or "serial:PATH".
struct BackendChoice {
  enum class Kind { null, audio, serial };
  Kind kind = Kind::null;
  std::string serial_path;  ///< Kind::serial: the tty or pseudo-terminal
};
/// Parses a backend name; throws FieldError("backend", ...) listing the
/// allowed names.
BackendChoice parse_backend(std::string_view name);

/// What the chosen backend is opened with.
struct BackendOptions {
  double rate_hz = 48000.0;       ///< the player's output rate (serial: frames streamed per second)
  std::size_t block_frames = 64;  ///< null and audio: frames per block
  std::string audio_device;       ///< audio: PortAudio device index or name substring
  int baud = 921600;              ///< serial
  SerialStream stream = SerialStream::position;
  std::shared_ptr<const NativeMap> serial_map;  ///< serial, position stream: SerialOptions::map
  std::size_t channels = 1;                     ///< null and audio: output channels (a ChannelPlayer's), 1 … 64; serial: 1
};
/// Opens the backend `choice` names. A serial display is given `map` first.
/// Throws like the make_*_backend functions.
std::unique_ptr<Backend> make_backend(const BackendChoice& choice, const BackendOptions& options, const PlayerMap& map);

}  // namespace texel
