// File sinks (WAV, CSV) and the real-time backends: null, PortAudio, serial.
#include "texel/sinks.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <thread>

#include <portaudio.h>
#include <time.h>
#include <unistd.h>

#include "texel/detail/format.hpp"
#include "texel/detail/realtime.hpp"
#include "texel/detail/shared_object.hpp"
#include "texel/detail/sndfile.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/multichannel_player.hpp"
#include "texel/serial_link.hpp"

namespace texel {

using Clock = std::chrono::steady_clock;

// ----------------------------------------------------------------- files

void write_wav(const std::string& path, std::span<const float> samples, double rate_hz, WavEncoding encoding) {
  write_wav(path, samples, 1, rate_hz, encoding);
}

void write_wav(const std::string& path, std::span<const float> samples, std::size_t channels, double rate_hz,
               WavEncoding encoding) {
  if (!(rate_hz >= 1 && rate_hz <= 1e6)) throw InvalidArgument("wav: rate is " + detail::num(rate_hz) + " Hz; allowed 1 … 1e6");
  if (channels < 1 || channels > 64 || samples.size() % channels != 0)
    throw InvalidArgument("wav: " + std::to_string(samples.size()) + " samples in " + std::to_string(channels) +
                          " channels; allowed: 1 … 64 channels and whole frames");
  check_writable(path);
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  const detail::SndFile& sf = detail::sndfile();  // opened here on the first WAV written
  SF_INFO info{};
  info.samplerate = static_cast<int>(std::lround(rate_hz));
  info.channels = static_cast<int>(channels);
  info.format = SF_FORMAT_WAV | (encoding == WavEncoding::pcm16   ? SF_FORMAT_PCM_16
                                 : encoding == WavEncoding::pcm24 ? SF_FORMAT_PCM_24
                                                                  : SF_FORMAT_FLOAT);
  SNDFILE* f = sf.sf_open(tmp.c_str(), SFM_WRITE, &info);
  if (!f) throw IoError("cannot write '" + path + "': " + sf.sf_strerror(nullptr));
  // Clip rather than let libsndfile wrap out-of-range floats.
  sf.sf_command(f, SFC_SET_CLIPPING, nullptr, SF_TRUE);
  const sf_count_t n = static_cast<sf_count_t>(samples.size() / channels);  // frames
  const sf_count_t written = n ? sf.sf_writef_float(f, samples.data(), n) : 0;
  const std::string err = written == n ? "" : sf.sf_strerror(f);
  if (sf.sf_close(f) != 0 || written != n) {
    std::remove(tmp.c_str());
    throw IoError("cannot write '" + path + "': " + (err.empty() ? "write failed" : err));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string e = std::strerror(errno);
    std::remove(tmp.c_str());
    throw IoError("cannot write '" + path + "': " + e);
  }
}

namespace {
// One row per output sample: time, the given position columns, output.
std::string signal_rows(const char* header, double rate_hz, std::span<const std::span<const float>> columns,
                        std::span<const float> output) {
  std::string out = header;
  out.reserve(out.size() + output.size() * (16 + 16 * columns.size()));
  char buf[64];
  for (std::size_t i = 0; i < output.size(); ++i) {
    out.append(buf, static_cast<std::size_t>(std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(i) / rate_hz)));
    for (const auto& c : columns)
      out.append(
          buf, static_cast<std::size_t>(std::snprintf(buf, sizeof buf, ",%.7g", i < c.size() ? static_cast<double>(c[i]) : 0.0)));
    out.append(buf, static_cast<std::size_t>(std::snprintf(buf, sizeof buf, ",%.7g\n", static_cast<double>(output[i]))));
  }
  return out;
}
}  // namespace

std::string signal_csv(double rate_hz, std::span<const float> positions_mm, std::span<const float> output) {
  const std::span<const float> cols[] = {positions_mm};
  return signal_rows("time_s,position_mm,output\n", rate_hz, cols, output);
}

std::string signal_csv(double rate_hz, std::span<const float> x_mm, std::span<const float> y_mm, std::span<const float> output) {
  const std::span<const float> cols[] = {x_mm, y_mm};
  return signal_rows("time_s,x_mm,y_mm,output\n", rate_hz, cols, output);
}

// --------------------------------------------------------------- Backend

BackendStats Backend::stats() {
  BackendStats s;
  s.blocks = blocks_.load(std::memory_order_relaxed);
  s.worst_block_s = static_cast<double>(worst_ns_.load(std::memory_order_relaxed)) * 1e-9;
  s.total_block_s = static_cast<double>(total_ns_.load(std::memory_order_relaxed)) * 1e-9;
  s.peak = peak_.exchange(0.0f, std::memory_order_relaxed);
  s.underruns = underruns_.load(std::memory_order_relaxed);
  s.position_mm = position_.load(std::memory_order_relaxed);
  s.touching = touching_.load(std::memory_order_relaxed);
  return s;
}

void Backend::start(PlayerBase& player) {
  stop();
  // A block holds frames × channels: the player's must be the backend's.
  const auto* multi = dynamic_cast<const ChannelPlayer*>(&player);
  const std::size_t player_channels = multi ? multi->channels() : 1;
  if (player_channels != channels())
    throw InvalidArgument("backend " + describe() + " has " + std::to_string(channels()) + " output channel" +
                          (channels() == 1 ? "" : "s") + "; the player has " + std::to_string(player_channels) +
                          " (open the backend with as many)");
  attachment_.attach(player);  // throws if another backend drives the player
  try {
    do_start(player);
  } catch (...) {
    attachment_.detach();
    throw;
  }
}

// The attachment goes only after the real-time side has stopped: a player
// that sees itself detached may be destroyed at once.
void Backend::stop() noexcept {
  do_stop();
  attachment_.detach();
}

// Real-time safe: relaxed atomic loads and stores only.
void Backend::record(const BlockInfo& info, double seconds) noexcept {
  const auto ns = static_cast<std::uint64_t>(seconds * 1e9);
  blocks_.fetch_add(1, std::memory_order_relaxed);
  total_ns_.fetch_add(ns, std::memory_order_relaxed);
  if (ns > worst_ns_.load(std::memory_order_relaxed)) worst_ns_.store(ns, std::memory_order_relaxed);
  if (info.peak > peak_.load(std::memory_order_relaxed)) peak_.store(info.peak, std::memory_order_relaxed);
  position_.store(info.position_mm, std::memory_order_relaxed);
  touching_.store(info.touching, std::memory_order_relaxed);
}

namespace {

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// ------------------------------------------------------- paced backends

// A backend whose own thread calls the player once per period, on deadlines
// counted from the start (so lateness does not accumulate): the null backend
// and the serial link share this. For the null backend, which stands in for a
// sound card, a block that starts more than a period late counts as an
// underrun; a serial display holds its last value, so a late frame is not one
// (count_late false). An exception from a tick (the serial link's I/O)
// ends the loop and is reported by error() instead of escaping the thread.
class PacedBackend : public Backend {
 public:
  /// What the loop's thread got (after start()): real-time or normal.
  [[nodiscard]] std::string scheduling() const override { return detail::describe(scheduling_.load(std::memory_order_relaxed)); }
  [[nodiscard]] std::string error() const override {
    std::lock_guard lock(error_mutex_);
    return error_;
  }

 protected:
  PacedBackend(double period_s, bool count_late) : period_(period_s), count_late_(count_late) {}
  // One period's work. process() inside it stays real-time safe; the tick
  // itself may do I/O (it runs on this backend's thread, not an audio one).
  virtual void tick(PlayerBase& player) = 0;
  // Before the thread starts (may throw: start() fails) and after it has
  // stopped (every stop, whatever ended the run).
  virtual void before_run() {}
  virtual void after_run() noexcept {}
  // Only before start().
  void set_period(double period_s) { period_ = std::chrono::duration<double>(period_s); }

 private:
  void do_start(PlayerBase& player) final {
    {
      std::lock_guard lock(error_mutex_);
      error_.clear();
    }
    before_run();
    running_ = true;
    thread_ = std::thread([this, &player] { loop(player); });
  }
  void do_stop() noexcept final {
    running_ = false;
    if (!thread_.joinable()) return;
    thread_.join();
    after_run();
  }
  void loop(PlayerBase& player) {
    scheduling_.store(detail::make_thread_realtime(), std::memory_order_relaxed);
    // Absolute deadlines on CLOCK_MONOTONIC (clock_nanosleep TIMER_ABSTIME):
    // lateness does not accumulate, and no relative sleep is stretched by
    // the time spent computing it.
    timespec t0{};
    ::clock_gettime(CLOCK_MONOTONIC, &t0);
    const auto ns_of = [](const timespec& t) { return static_cast<std::int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec; };
    const std::int64_t start = ns_of(t0);
    const auto period_ns = static_cast<std::int64_t>(std::llround(period_.count() * 1e9));
    try {
      for (std::uint64_t k = 0; running_.load(std::memory_order_relaxed); ++k) {
        const std::int64_t deadline =
            start + static_cast<std::int64_t>(std::llround(period_.count() * 1e9 * static_cast<double>(k)));
        timespec now{};
        ::clock_gettime(CLOCK_MONOTONIC, &now);
        if (count_late_ && ns_of(now) > deadline + period_ns) record_underrun();
        const timespec until{static_cast<time_t>(deadline / 1000000000), static_cast<long>(deadline % 1000000000)};
        while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR) {
        }
        tick(player);
      }
    } catch (const std::exception& e) {
      std::lock_guard lock(error_mutex_);
      error_ = e.what();
    }
  }
  std::chrono::duration<double> period_;
  bool count_late_;
  std::atomic<detail::ThreadScheduling> scheduling_{detail::ThreadScheduling{}};
  std::atomic<bool> running_{false};
  std::thread thread_;
  mutable std::mutex error_mutex_;
  std::string error_;
};

// ------------------------------------------------------------------ null

class NullBackend final : public PacedBackend {
 public:
  NullBackend(double rate, std::size_t block, std::size_t channels)
      : PacedBackend(checked_period(rate, block), true),
        rate_(rate),
        channels_(checked_channels(channels)),
        buffer_(block * channels_) {}
  ~NullBackend() override { stop(); }
  [[nodiscard]] std::string describe() const override {
    return "null (no output device), " + detail::num(rate_) + " Hz, " + std::to_string(buffer_.size() / channels_) +
           " frames per block" + (channels_ > 1 ? ", " + std::to_string(channels_) + " channels" : "");
  }
  [[nodiscard]] std::size_t channels() const noexcept override { return channels_; }

 private:
  static double checked_period(double rate, std::size_t block) {
    if (!(rate >= 100 && rate <= 384000))
      throw InvalidArgument("null backend: rate is " + detail::num(rate) + " Hz; allowed 100 … 384000");
    if (block < 1 || block > 65536)
      throw InvalidArgument("null backend: block is " + std::to_string(block) + " frames; allowed 1 … 65536");
    return static_cast<double>(block) / rate;
  }
  static std::size_t checked_channels(std::size_t channels) {
    if (channels < 1 || channels > 64)
      throw InvalidArgument("null backend: channels is " + std::to_string(channels) + "; allowed 1 … 64");
    return channels;
  }
  void tick(PlayerBase& player) override {
    const auto b0 = Clock::now();
    const BlockInfo info = player.process(buffer_);
    record(info, seconds_since(b0));
  }
  double rate_;
  std::size_t channels_;
  std::vector<float> buffer_;
};

// ------------------------------------------------------------- PortAudio

// PortAudio is opened on first use (dlopen), not linked: it brings JACK and
// ALSA, loaded by every texel command at start-up otherwise; only live
// playback needs it.
#ifndef TEXEL_PORTAUDIO_SONAME
#error "TEXEL_PORTAUDIO_SONAME (PortAudio's shared object name) is set by src/CMakeLists.txt"
#endif

// clang-format off
#define TEXEL_PORTAUDIO_FUNCTIONS(X) \
  X(Pa_CloseStream) \
  X(Pa_GetDefaultOutputDevice) \
  X(Pa_GetDeviceCount) \
  X(Pa_GetDeviceInfo) \
  X(Pa_GetErrorText) \
  X(Pa_GetHostApiInfo) \
  X(Pa_Initialize) \
  X(Pa_IsStreamStopped) \
  X(Pa_OpenStream) \
  X(Pa_StartStream) \
  X(Pa_StopStream) \
  X(Pa_Terminate)
// clang-format on

/// PortAudio, opened when the first audio sink or device list is made
/// (`portaudio()`).
TEXEL_SHARED_LIBRARY(PortAudio, portaudio, TEXEL_PORTAUDIO_SONAME, "audio output and device lists", TEXEL_PORTAUDIO_FUNCTIONS)

void pa_check(PaError e, const std::string& what) {
  if (e != paNoError) throw IoError("audio: " + what + ": " + portaudio().Pa_GetErrorText(e));
}

class PaSession {
 public:
  PaSession() {
    // PortAudio probes every host API on initialisation and some (ALSA, JACK)
    // print to stderr when no server or card exists; silence them.
    std::fflush(stderr);
    const int saved = ::dup(2);
    std::FILE* devnull = std::fopen("/dev/null", "w");
    if (devnull && saved >= 0) ::dup2(::fileno(devnull), 2);
    const PaError e = portaudio().Pa_Initialize();
    if (saved >= 0) {
      ::dup2(saved, 2);
      ::close(saved);
    }
    if (devnull) std::fclose(devnull);
    pa_check(e, "cannot initialise PortAudio");
  }
  ~PaSession() { portaudio().Pa_Terminate(); }
  PaSession(const PaSession&) = delete;
  PaSession& operator=(const PaSession&) = delete;
};

std::vector<std::string> list_outputs() {
  std::vector<std::string> out;
  const int n = portaudio().Pa_GetDeviceCount();
  for (int i = 0; i < n; ++i) {
    const PaDeviceInfo* d = portaudio().Pa_GetDeviceInfo(i);
    if (!d || d->maxOutputChannels < 1) continue;
    const PaHostApiInfo* h = portaudio().Pa_GetHostApiInfo(d->hostApi);
    out.push_back(std::to_string(i) + ": " + d->name + " (" + (h ? h->name : "?") + ", " + std::to_string(d->maxOutputChannels) +
                  " ch, default " + detail::num(d->defaultSampleRate) + " Hz)");
  }
  return out;
}

class AudioBackend final : public Backend {
 public:
  explicit AudioBackend(const AudioOptions& o) : options_(o) {
    PaDeviceIndex dev = paNoDevice;
    if (o.device.empty()) {
      dev = portaudio().Pa_GetDefaultOutputDevice();
    } else {
      char* end = nullptr;
      const long idx = std::strtol(o.device.c_str(), &end, 10);
      if (end && *end == '\0' && idx >= 0 && idx < portaudio().Pa_GetDeviceCount()) {
        dev = static_cast<PaDeviceIndex>(idx);
      } else {
        for (int i = 0; i < portaudio().Pa_GetDeviceCount(); ++i) {
          const PaDeviceInfo* d = portaudio().Pa_GetDeviceInfo(i);
          if (d && d->maxOutputChannels > 0 && std::string(d->name).find(o.device) != std::string::npos) {
            dev = i;
            break;
          }
        }
      }
    }
    if (dev == paNoDevice || !portaudio().Pa_GetDeviceInfo(dev) || portaudio().Pa_GetDeviceInfo(dev)->maxOutputChannels < 1) {
      std::string list;
      for (const auto& s : list_outputs()) list += (list.empty() ? "" : "; ") + s;
      throw IoError("audio: no output device '" + (o.device.empty() ? std::string("default") : o.device) +
                    "'; outputs: " + (list.empty() ? "none (use --backend null)" : list));
    }
    const PaDeviceInfo* info = portaudio().Pa_GetDeviceInfo(dev);
    device_name_ = info->name;
    PaStreamParameters p{};
    p.device = dev;
    if (o.channels < 1 || o.channels > 64 || static_cast<int>(o.channels) > info->maxOutputChannels)
      throw IoError("audio: '" + device_name_ + "' has " + std::to_string(info->maxOutputChannels) +
                    " output channels; asked for " + std::to_string(o.channels) + " (allowed 1 … " +
                    std::to_string(std::min(64, info->maxOutputChannels)) + ")");
    p.channelCount = static_cast<int>(o.channels);
    p.sampleFormat = paFloat32;
    p.suggestedLatency = o.latency_s > 0 ? o.latency_s : info->defaultLowOutputLatency;
    pa_check(
        portaudio().Pa_OpenStream(&stream_, nullptr, &p, o.rate_hz, static_cast<unsigned long>(o.block_frames), paClipOff,
                                  &AudioBackend::callback, this),
        "cannot open '" + device_name_ + "' at " + detail::num(o.rate_hz) + " Hz, " + std::to_string(o.block_frames) + " frames");
  }
  ~AudioBackend() override {
    stop();
    if (stream_) portaudio().Pa_CloseStream(stream_);
  }
  [[nodiscard]] std::string describe() const override {
    return "audio '" + device_name_ + "', " + detail::num(options_.rate_hz) + " Hz, " + std::to_string(options_.block_frames) +
           " frames per block" + (options_.channels > 1 ? ", " + std::to_string(options_.channels) + " channels" : "");
  }
  [[nodiscard]] std::size_t channels() const noexcept override { return options_.channels; }

 private:
  void do_start(PlayerBase& player) override {
    player_ = &player;
    pa_check(portaudio().Pa_StartStream(stream_), "cannot start '" + device_name_ + "'");
  }
  // Pa_StopStream returns after the last callback has returned.
  void do_stop() noexcept override {
    if (stream_ && portaudio().Pa_IsStreamStopped(stream_) == 0) portaudio().Pa_StopStream(stream_);
    player_ = nullptr;
  }
  // PortAudio's callback: calls only the real-time-safe process() and
  // relaxed atomics.
  static int callback(const void*, void* output, unsigned long frames, const PaStreamCallbackTimeInfo*,
                      PaStreamCallbackFlags flags, void* self_ptr) {
    auto* self = static_cast<AudioBackend*>(self_ptr);
    if (flags & paOutputUnderflow) self->record_underrun();
    const auto t0 = Clock::now();
    // Interleaved frames × channels (a ChannelPlayer's, or one channel).
    const BlockInfo info = self->player_->process(std::span(static_cast<float*>(output), frames * self->options_.channels));
    self->record(info, seconds_since(t0));
    return paContinue;
  }
  PaSession session_;  // initialised before the stream, terminated after it
  AudioOptions options_;
  PaStream* stream_ = nullptr;
  PlayerBase* player_ = nullptr;
  std::string device_name_;
};

// ---------------------------------------------------------------- serial

// Safe by default: every stop (end, pause, error, a signal handled by the
// caller, destruction while unwinding) sends rest — DRIVE 0 and SELECT none —
// once the streaming thread has ended; the display's 200 ms watchdog covers
// the host that cannot (SIGKILL, a cut cable).
class SerialBackend final : public PacedBackend {
 public:
  SerialBackend(const SerialOptions& o, const PlayerMap& map)
      : PacedBackend(checked_period(o.rate_hz), false), options_(o), link_(o.path, o.baud) {
    info_ = link_.hello();
    // Positions or values streamed faster than the display refreshes are
    // never output: stream at most at its refresh rate.
    if (options_.rate_hz > info_.refresh_hz) {
      options_.rate_hz = info_.refresh_hz;
      set_period(1.0 / info_.refresh_hz);
    }
    if (o.stream == SerialStream::position) {
      if (o.map)
        link_.upload(0, *o.map);
      else
        link_.upload_map(0, map);
      link_.select(0);
    }
  }
  ~SerialBackend() override { stop(); }
  [[nodiscard]] SerialLink* serial_link() noexcept override { return &link_; }
  [[nodiscard]] std::string describe() const override {
    return "serial " + options_.path + " → '" + info_.name + "' (protocol " + std::to_string(info_.version) + ", " +
           detail::num(info_.refresh_hz) + " Hz refresh), streaming " +
           (options_.stream == SerialStream::position ? "positions" : "drive values") + " at " + detail::num(options_.rate_hz) +
           " Hz";
  }

 private:
  static double checked_period(double rate_hz) {
    if (!(rate_hz >= 1 && rate_hz <= 20000))
      throw InvalidArgument("serial backend: rate is " + detail::num(rate_hz) + " Hz; allowed 1 … 20000");
    return 1.0 / rate_hz;
  }
  void before_run() override {
    if (options_.stream == SerialStream::position && rested_) link_.select(0);  // rest() deselected it
    rested_ = false;
  }
  void after_run() noexcept override {
    link_.rest();
    rested_ = true;
  }
  // The streaming thread does I/O by nature; process() itself stays
  // real-time safe.
  void tick(PlayerBase& player) override {
    float out[1];
    float pos[1];
    const auto b0 = Clock::now();
    const BlockInfo info = player.process(out, pos);
    record(info, seconds_since(b0));
    if (options_.stream == SerialStream::position)
      link_.stream_position(pos[0], info.touching);
    else
      link_.stream_drive(out[0]);
  }
  SerialOptions options_;
  SerialLink link_;
  DisplayInfo info_;
  bool rested_ = false;
};

}  // namespace

std::unique_ptr<Backend> make_null_backend(double rate_hz, std::size_t block_frames, std::size_t channels) {
  return std::make_unique<NullBackend>(rate_hz, block_frames, channels);
}

std::unique_ptr<Backend> make_audio_backend(const AudioOptions& options) { return std::make_unique<AudioBackend>(options); }

std::vector<std::string> audio_output_devices() {
  PaSession session;
  return list_outputs();
}

BackendChoice parse_backend(std::string_view name) {
  if (name == "null") return {BackendChoice::Kind::null, {}};
  if (name == "audio") return {BackendChoice::Kind::audio, {}};
  if (name.starts_with("serial:") && name.size() > 7) return {BackendChoice::Kind::serial, std::string(name.substr(7))};
  throw FieldError("backend", "is '" + std::string(name) + "'; allowed: null, audio, serial:PATH");
}

std::unique_ptr<Backend> make_backend(const BackendChoice& choice, const BackendOptions& options, const PlayerMap& map) {
  switch (choice.kind) {
    case BackendChoice::Kind::null: return make_null_backend(options.rate_hz, options.block_frames, options.channels);
    case BackendChoice::Kind::audio: {
      AudioOptions o;
      o.device = options.audio_device;
      o.rate_hz = options.rate_hz;
      o.block_frames = options.block_frames;
      o.channels = options.channels;
      return make_audio_backend(o);
    }
    case BackendChoice::Kind::serial: break;
  }
  if (options.channels != 1)
    throw InvalidArgument("backend serial: a display takes one channel; the player has " + std::to_string(options.channels));
  SerialOptions o;
  o.path = choice.serial_path;
  o.baud = options.baud;
  o.rate_hz = options.rate_hz;
  o.stream = options.stream;
  o.map = options.serial_map;
  return make_serial_backend(o, map);
}

std::unique_ptr<Backend> make_serial_backend(const SerialOptions& options, const PlayerMap& map) {
  return std::make_unique<SerialBackend>(options, map);
}

}  // namespace texel
