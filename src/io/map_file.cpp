// Streaming map writer (include/texel/map_file.hpp).
#include "texel/map_file.hpp"

#include <algorithm>
#include <charconv>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "texel/detail/parallel.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

namespace texel {
namespace {

/// One chunk of the map: its amplitudes, their sum and the bytes they encode to.
struct Chunk {
  std::vector<double> amplitudes;
  std::vector<std::byte> encoded;  // .bin
  std::string text;                // .csv
  double sum = 0.0;
};

/// The sum of `a` in a fixed blocked order: eight running sums (element i
/// into sum i mod 8), added pairwise at the end. Eight independent chains
/// instead of one (a double add's latency per sample), and the order is a
/// function of the chunk alone, so the total does not depend on which thread
/// summed it or how many there were.
double blocked_sum(std::span<const double> a) {
  double s[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  std::size_t i = 0;
  for (; i + 8 <= a.size(); i += 8)
    for (std::size_t l = 0; l < 8; ++l) s[l] += a[i + l];
  for (std::size_t l = 0; i < a.size(); ++i, ++l) s[l] += a[i];
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

/// Renders, sums and encodes chunk `index` (samples index·chunk …) into `c`.
/// A pure function of the index: any thread may run it for any chunk.
struct ChunkMaker {
  const Surface& surface;
  MapFileKind kind;
  SampleFormat format;
  std::size_t chunk;
  std::size_t samples;

  void operator()(std::size_t index, Chunk& c) const {
    const std::size_t first = index * chunk;
    const std::size_t len = std::min(chunk, samples - first);
    c.amplitudes.resize(len);
    const std::span<double> a(c.amplitudes);
    surface.render(static_cast<std::int64_t>(first), a);
    c.sum = blocked_sum(a);
    switch (kind) {
      case MapFileKind::device_native:
        c.encoded.resize(len * bytes_per_sample(format));
        encode_samples(format, a, c.encoded);
        break;
      case MapFileKind::npy: break;  // the doubles are the bytes
      case MapFileKind::csv: {
        // The bytes of csv_columns: shortest round-trip text of each value.
        const Grid& g = surface.grid();
        c.text.clear();
        char buf[64];
        for (std::size_t i = 0; i < len; ++i) {
          auto r = std::to_chars(buf, buf + sizeof buf, g.position(static_cast<std::int64_t>(first + i)).value());
          c.text.append(buf, r.ptr);
          c.text.push_back(',');
          r = std::to_chars(buf, buf + sizeof buf, a[i]);
          c.text.append(buf, r.ptr);
          c.text.push_back('\n');
        }
        break;
      }
    }
  }

  [[nodiscard]] std::span<const std::byte> bytes(const Chunk& c) const {
    switch (kind) {
      case MapFileKind::device_native: return c.encoded;
      case MapFileKind::npy: return std::as_bytes(std::span<const double>(c.amplitudes));
      case MapFileKind::csv: return std::as_bytes(std::span<const char>(c.text.data(), c.text.size()));
    }
    return {};
  }
};

/// Chunks 0 … count−1 made by `threads` threads, the calling thread among
/// them, and taken by the calling thread strictly in order (take), written,
/// and given back (give_back). A chunk lives in slot index mod slots until it
/// is given back, so at most `slots` chunks are in memory whatever the map's
/// length. While the chunk it wants is still being made, the calling thread
/// makes the next chunk nobody has started (so `threads` threads, not one
/// more, share the cores, and the caller rarely sleeps). A worker's exception
/// stops the others and is rethrown by take; the destructor (normal end, or
/// an exception in the calling thread) stops the workers and joins them
/// before the slots go.
class ChunkPipeline {
 public:
  ChunkPipeline(const ChunkMaker& make, std::size_t count, unsigned threads)
      : make_(make), count_(count), slots_(2 * static_cast<std::size_t>(threads)), made_(slots_.size(), false) {
    try {
      for (unsigned w = 1; w < threads; ++w) workers_.emplace_back([this] { work(); });
    } catch (...) {
      stop();
      throw;
    }
  }
  ~ChunkPipeline() { stop(); }
  ChunkPipeline(const ChunkPipeline&) = delete;
  ChunkPipeline& operator=(const ChunkPipeline&) = delete;

  /// Chunk `index`, once made (the caller takes 0, 1, 2, … in order).
  const Chunk& take(std::size_t index) {
    std::unique_lock lock(mutex_);
    for (;;) {
      if (error_) std::rethrow_exception(error_);
      if (made_[slot(index)]) return slots_[slot(index)];
      if (startable()) {
        const std::size_t mine = next_++;
        lock.unlock();
        make_(mine, slots_[slot(mine)]);  // throws past take: the destructor stops the workers
        lock.lock();
        made_[slot(mine)] = true;
        continue;
      }
      awaited_ = index;
      made_cv_.wait(lock);
      awaited_ = none;
    }
  }
  /// Chunk `index` is written: its slot may take chunk index + slots.
  void give_back(std::size_t index) {
    {
      const std::lock_guard lock(mutex_);
      made_[slot(index)] = false;
      given_back_ = index + 1;
    }
    free_cv_.notify_one();
  }

 private:
  static constexpr std::size_t none = ~std::size_t{0};

  [[nodiscard]] std::size_t slot(std::size_t index) const { return index % slots_.size(); }
  /// A chunk nobody has started, with a free slot (under the lock).
  [[nodiscard]] bool startable() const { return next_ < count_ && next_ < given_back_ + slots_.size(); }

  void work() {
    for (;;) {
      std::size_t index = 0;
      {
        std::unique_lock lock(mutex_);
        free_cv_.wait(lock, [&] { return stopping_ || next_ >= count_ || startable(); });
        if (stopping_ || next_ >= count_) return;
        index = next_++;
      }
      try {
        make_(index, slots_[slot(index)]);
      } catch (...) {
        {
          const std::lock_guard lock(mutex_);
          if (!error_) error_ = std::current_exception();
          stopping_ = true;
        }
        made_cv_.notify_one();
        free_cv_.notify_all();
        return;
      }
      bool wake = false;
      {
        const std::lock_guard lock(mutex_);
        made_[slot(index)] = true;
        wake = awaited_ == index;  // the caller sleeps until this very chunk
      }
      if (wake) made_cv_.notify_one();
    }
  }

  void stop() {
    {
      const std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    free_cv_.notify_all();
    for (auto& t : workers_) t.join();
    workers_.clear();
  }

  const ChunkMaker& make_;
  const std::size_t count_;
  std::vector<Chunk> slots_;
  std::vector<bool> made_;      // per slot: holds its chunk, not yet given back
  std::size_t next_ = 0;        // the next chunk nobody has started
  std::size_t given_back_ = 0;  // chunks the caller has written
  std::size_t awaited_ = none;  // the chunk the caller sleeps for
  bool stopping_ = false;
  std::exception_ptr error_;
  std::mutex mutex_;
  std::condition_variable made_cv_;  // the caller waits for a chunk
  std::condition_variable free_cv_;  // workers wait for a slot
  std::vector<std::thread> workers_;
};

}  // namespace

std::optional<MapFileKind> map_file_kind(const std::string& path) {
  const std::string ext = output_extension(path);
  if (ext == ".bin") return MapFileKind::device_native;
  if (ext == ".csv") return MapFileKind::csv;
  if (ext == ".npy") return MapFileKind::npy;
  return std::nullopt;
}

unsigned map_file_threads(unsigned requested) {
  if (requested > 0) return requested;
  return static_cast<unsigned>(detail::worker_threads(static_cast<int>(MapFileOptions::max_auto_threads)));
}

MapFileStats write_map(const std::string& path, const Surface& surface, SampleFormat format, const MapFileOptions& options) {
  const auto kind = map_file_kind(path);
  if (!kind) throw InvalidArgument("output '" + path + "': a streamed map is .bin, .csv or .npy");
  if (options.chunk_samples == 0) throw InvalidArgument("chunk_samples is 0; it must be > 0");
  const Grid& g = surface.grid();
  const auto n = static_cast<std::size_t>(g.count);
  const std::size_t chunk = std::min(options.chunk_samples, std::max<std::size_t>(n, 1));
  const std::size_t chunks = (n + chunk - 1) / chunk;
  const ChunkMaker make{surface, *kind, format, chunk, n};
  // Threads beyond the chunks would have nothing to do; one renders on the
  // calling thread, as a map of one chunk always does.
  const auto threads = static_cast<unsigned>(std::min<std::size_t>(map_file_threads(options.threads), chunks));

  AtomicFile file(path);
  if (*kind == MapFileKind::csv) file.write(std::string_view("position_mm,amplitude\n"));
  if (*kind == MapFileKind::npy) file.write(npy_header(n));
  double sum = 0.0;
  {
    // Declared after the file: on an exception the workers stop and are
    // joined before the file's temporary is removed.
    std::optional<ChunkPipeline> pipeline;
    Chunk local;
    if (threads > 1) pipeline.emplace(make, chunks, threads);
    for (std::size_t i = 0; i < chunks; ++i) {
      const Chunk* c = &local;
      if (pipeline)
        c = &pipeline->take(i);
      else
        make(i, local);
      file.write(make.bytes(*c));
      sum += c->sum;
      if (pipeline) pipeline->give_back(i);
      if (options.progress) options.progress(static_cast<double>(std::min(n, (i + 1) * chunk)) / static_cast<double>(n));
    }
  }
  file.commit();
  MapFileStats stats;
  stats.samples = n;
  stats.mean_amplitude = n ? sum / static_cast<double>(n) : 0.0;
  std::error_code ec;
  stats.bytes = static_cast<std::size_t>(std::filesystem::file_size(path, ec));
  return stats;
}

}  // namespace texel
