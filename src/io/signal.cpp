// The one signal loader (texel/signal.hpp): every command and binding reads
// texture signals through load_signal(). Each format is parsed from bytes
// (decode_signal, so fuzzers and servers need no file); the file entry point
// only bounds the file's size before reading it. Audio goes through
// libsndfile's virtual I/O from memory, or sf_open on a path (no copy);
// libsndfile is opened on the first audio file (texel/detail/sndfile.hpp).
#include "texel/signal.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "texel/detail/format.hpp"
#include "texel/detail/sndfile.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/matfile.hpp"
#include "texel/surface.hpp"

namespace texel {
namespace {

using detail::num;

std::string in_quotes(std::string_view origin) { return "'" + std::string(origin) + "'"; }

/// Checks the options that do not depend on the file.
void validate(const SignalOptions& o) {
  if (o.spacing && !(std::isfinite(o.spacing->value()) && o.spacing->value() > 0.0))
    throw FieldError("spacing", "is " + num(o.spacing->value()) + " mm; it must be a finite number > 0");
  if (o.swipe_speed && !(std::isfinite(o.swipe_speed->value()) && o.swipe_speed->value() > 0.0))
    throw FieldError("swipe_speed", "is " + num(o.swipe_speed->value()) + " mm/s; it must be a finite speed > 0");
  if (o.region && o.region->name.empty() && !(o.region->start < o.region->end))
    throw FieldError(
        "region", "[" + num(o.region->start.value()) + ", " + num(o.region->end.value()) + ") mm is empty; it needs start < end");
  if (o.max_samples < 2) throw FieldError("max_samples", "is " + std::to_string(o.max_samples) + "; it must be >= 2");
}

[[noreturn]] void too_many(std::string_view origin, std::size_t declared, const SignalOptions& o) {
  throw FieldError("max_samples", "is " + std::to_string(o.max_samples) + "; " + in_quotes(origin) + " declares " +
                                      std::to_string(declared) + " samples");
}

MmPerSecond need_speed(const SignalOptions& o, std::string_view origin) {
  if (!o.swipe_speed)
    throw FieldError("swipe_speed", "is required: " + in_quotes(origin) +
                                        " is a time recording, and the swipe speed (mm/s) turns its time into position");
  return *o.swipe_speed;
}

/// A file's own spacing must agree with an explicit one (spacing_tolerance).
void check_spacing(double own, const SignalOptions& o, std::string_view origin) {
  if (o.spacing && std::fabs(o.spacing->value() - own) > spacing_tolerance * own)
    throw FieldError("spacing", "is " + num(o.spacing->value()) + " mm, but " + in_quotes(origin) + " is sampled every " +
                                    num(own) + " mm (allowed difference " + num(100 * spacing_tolerance) + " %)");
}

/// The step of a sampled axis, which must be uniform to spacing_tolerance.
double uniform_step(const std::vector<double>& axis, std::string_view origin, const char* what) {
  if (axis.size() < 2) throw FormatError(in_quotes(origin) + " has fewer than 2 rows");
  const double step = (axis.back() - axis.front()) / static_cast<double>(axis.size() - 1);
  if (!(step > 0.0 && std::isfinite(step))) throw FormatError(in_quotes(origin) + ": the " + what + " column must increase");
  for (std::size_t i = 1; i < axis.size(); ++i)
    if (!(std::fabs(axis[i] - axis[i - 1] - step) <= spacing_tolerance * step))
      throw FormatError(in_quotes(origin) + ": the " + what + " column is not uniformly sampled at data row " +
                        std::to_string(i + 1) + " (step " + num(axis[i] - axis[i - 1]) + ", mean step " + num(step) +
                        ", allowed difference " + num(100 * spacing_tolerance) + " %)");
  return step;
}

/// Full range: a = 0.5 + 0.5·y/max|y|, y the zero-mean signal (docs/references.md §1).
void scale_full_range(std::span<double> y, std::string_view origin) {
  double mean = 0.0;
  for (double v : y) mean += v;
  mean /= static_cast<double>(y.size());
  double peak = 0.0;
  for (double& v : y) v -= mean, peak = std::max(peak, std::fabs(v));
  if (!(peak > 0.0)) throw FormatError(in_quotes(origin) + " is constant: it holds no texture");
  for (double& v : y) v = 0.5 + 0.5 * v / peak;
}

Millimetres device_spacing(const SignalOptions& o, std::string_view origin, const char* what) {
  if (o.spacing) return *o.spacing;
  if (o.device) return o.device->spacing;
  throw FieldError("spacing", std::string("is required: ") + in_quotes(origin) + " " + what +
                                  " stores no sample spacing; give it, or a device whose spacing applies");
}

Signal from_recording(Recording r, const SignalOptions& o, std::string_view origin) {
  const MmPerSecond v = need_speed(o, origin);
  Signal s;
  s.samples = std::move(r.samples);
  s.spacing = Millimetres(v.value() / r.rate.value());
  check_spacing(s.spacing.value(), o, origin);
  s.sample_rate = r.rate;
  s.format = SignalFormat::wav;
  s.description = "audio " + num(r.rate.value()) + " Hz at " + num(v.value()) + " mm/s";
  return s;
}

// ---- libsndfile from memory (virtual I/O) --------------------------------

struct Memory {
  std::span<const std::byte> bytes;
  sf_count_t at = 0;
};
sf_count_t mem_length(void* u) { return static_cast<sf_count_t>(static_cast<Memory*>(u)->bytes.size()); }
sf_count_t mem_seek(sf_count_t offset, int whence, void* u) {
  auto* m = static_cast<Memory*>(u);
  const auto size = static_cast<sf_count_t>(m->bytes.size());
  const sf_count_t base = whence == SEEK_CUR ? m->at : whence == SEEK_END ? size : 0;
  m->at = std::clamp<sf_count_t>(base + offset, 0, size);
  return m->at;
}
sf_count_t mem_read(void* ptr, sf_count_t count, void* u) {
  auto* m = static_cast<Memory*>(u);
  const sf_count_t n = std::clamp<sf_count_t>(count, 0, static_cast<sf_count_t>(m->bytes.size()) - m->at);
  std::memcpy(ptr, m->bytes.data() + m->at, static_cast<std::size_t>(n));
  m->at += n;
  return n;
}
sf_count_t mem_write(const void*, sf_count_t, void*) { return 0; }
sf_count_t mem_tell(void* u) { return static_cast<Memory*>(u)->at; }

/// Reads an open sound file into mono samples under the channel policy;
/// sizes are checked before the buffer is allocated.
Recording read_open(SNDFILE* f, const SF_INFO& info, const SignalOptions& o, std::string_view origin) {
  struct Closer {
    SNDFILE* f;
    ~Closer() { detail::sndfile().sf_close(f); }
  } closer{f};
  if (info.frames <= 0 || info.channels <= 0 || info.samplerate <= 0)
    throw FormatError(in_quotes(origin) + " holds no audio frames");
  const auto channels = static_cast<unsigned>(info.channels);
  if (channels > 1 && o.channels == ChannelPolicy::mono_only)
    throw FieldError("channel", "is not chosen, and " + in_quotes(origin) + " has " + std::to_string(channels) +
                                    " channels; pick one (0 … " + std::to_string(channels - 1) + ") or mix them");
  if (o.channels == ChannelPolicy::select && o.channel >= channels)
    throw FieldError("channel", "is " + std::to_string(o.channel) + ", but " + in_quotes(origin) + " has " +
                                    std::to_string(channels) + " channel" + (channels == 1 ? "" : "s") + " (0 … " +
                                    std::to_string(channels - 1) + ")");
  const auto frames = static_cast<std::uint64_t>(info.frames);
  if (frames > o.max_samples || frames * channels > o.max_samples) too_many(origin, frames * channels, o);
  std::vector<double> all(frames * channels);
  const sf_count_t got = detail::sndfile().sf_readf_double(f, all.data(), info.frames);
  if (got != info.frames) throw FormatError(in_quotes(origin) + ": truncated audio data");
  Recording r;
  r.rate = Hertz(info.samplerate);
  r.channels = channels;
  r.samples.resize(frames);
  for (std::size_t i = 0; i < frames; ++i) {
    const double* frame = all.data() + i * channels;
    if (o.channels == ChannelPolicy::mix) {
      double s = 0.0;
      for (unsigned c = 0; c < channels; ++c) s += frame[c];
      r.samples[i] = s / channels;
    } else {
      r.samples[i] = frame[o.channels == ChannelPolicy::select ? o.channel : 0];
    }
  }
  return r;
}

// ---- the other formats from bytes ------------------------------------------

Signal decode_device_map(std::span<const std::byte> bytes, const SignalOptions& o, std::string_view origin) {
  if (!o.device)
    throw FieldError("device", "is required: " + in_quotes(origin) +
                                   " is a device map (.bin), whose sample format and spacing only its device profile gives");
  const DeviceProfile& d = *o.device;
  const std::size_t width = bytes_per_sample(d.format);
  if (bytes.empty() || bytes.size() % width != 0)
    throw FormatError(in_quotes(origin) + " has " + std::to_string(bytes.size()) + " bytes, not a whole number of " +
                      std::string(to_string(d.format)) + " samples of device '" + d.name + "'");
  if (bytes.size() / width > o.max_samples) too_many(origin, bytes.size() / width, o);
  Signal s;
  s.samples = decode_samples(d.format, bytes);
  s.spacing = o.spacing.value_or(d.spacing);
  s.description = "device map (" + d.name + ", " + std::string(to_string(d.format)) + ")";
  return s;
}

Signal decode_csv(std::string_view text, const SignalOptions& o, std::string_view origin) {
  std::vector<double> x;
  std::vector<double> y;
  // Two columns, or three as `texel swipe` writes them (time_s,position_mm,
  // output: a recording whose value is the last column), in every row.
  std::size_t columns = 0;
  const std::string header =
      read_numeric_csv(text, origin, 2, 3, "position_mm,amplitude, time_s,value or time_s,position_mm,value",
                       [&](std::size_t line, std::span<const double> v) {
                         if (columns == 0) columns = v.size();
                         if (v.size() != columns)
                           throw FormatError(in_quotes(origin) + ":" + std::to_string(line) + ": " + std::to_string(v.size()) +
                                             " columns where the first row has " + std::to_string(columns));
                         if (x.size() == o.max_samples) too_many(origin, x.size() + 1, o);
                         x.push_back(v[0]);
                         y.push_back(v.back());
                       });
  if (x.empty()) throw FormatError(in_quotes(origin) + " holds no numeric rows");
  // A header whose first column starts with 't' ("time", "t_s") marks a recording.
  const auto first = header.find_first_not_of(" \t\"");
  const bool is_time = first != std::string::npos && (header[first] == 't' || header[first] == 'T');
  if (columns == 3 && !is_time)
    throw FormatError(in_quotes(origin) + " has 3 columns, read only as time_s,position_mm,value (a recording, as " +
                      "texel swipe writes it); its header does not start with a time column");
  Signal s;
  if (is_time) {
    const MmPerSecond v = need_speed(o, origin);
    const double dt = uniform_step(x, origin, "time");
    s.spacing = Millimetres(v.value() * dt);
    s.origin = Millimetres(v.value() * x.front());
    s.sample_rate = Hertz(1.0 / dt);
    s.description = "time/value CSV at " + num(v.value()) + " mm/s";
    s.samples = std::move(y);
  } else {
    s.spacing = Millimetres(uniform_step(x, origin, "position"));
    s.origin = Millimetres(x.front());
    s.description = "position/amplitude CSV";
    s.samples = std::move(y);
  }
  check_spacing(s.spacing.value(), o, origin);
  return s;
}

/// The document's device: re-targeted to `device`, re-gridded at `spacing`.
/// A region chosen by name or index comes back as its span on the surface.
Signal render_document(Document doc, const SignalOptions& o, std::string_view origin,
                       std::optional<SignalOptions::Region>& span) {
  if (o.device) doc.device = *o.device;
  if (o.spacing) doc.device = with_grid(doc.device, std::nullopt, o.spacing);
  if (doc.device.samples > 0 && static_cast<std::uint64_t>(doc.device.samples) > o.max_samples)
    too_many(origin, static_cast<std::size_t>(doc.device.samples), o);
  const Surface surface = prepare_surface(doc);
  Signal s;
  s.samples = surface.render();
  s.spacing = surface.grid().spacing;
  s.origin = Millimetres(surface.grid().position(0));
  s.description = "document on " + doc.device.name;
  if (o.region && !o.region->name.empty()) {
    const auto& regions = surface.regions();
    const Region* chosen = nullptr;
    for (std::size_t i = 0; i < regions.size(); ++i)
      if (regions[i].name == o.region->name || std::to_string(i) == o.region->name) chosen = &regions[i];
    if (!chosen) {
      std::string names;
      for (std::size_t i = 0; i < regions.size(); ++i)
        names += (names.empty() ? "" : ", ") + (regions[i].name.empty() ? std::to_string(i) : regions[i].name);
      throw FieldError("region", "'" + o.region->name + "' is not in " + in_quotes(origin) + "; its regions: " + names);
    }
    s.description += ", region " + o.region->name;
    span = SignalOptions::Region{o.region->name, chosen->start, chosen->start + chosen->length};
  }
  return s;
}

/// An MPEG-I Haptics file's curves sampled on a grid (docs/interchange.md
/// "Import"): the given device's (re-gridded at `spacing`), else the carried
/// Texel document's device, else a built-in device the file names as its
/// reference device, else `spacing` (or, for temporal files, the channel's
/// sampling rate at the swipe speed) from 0 to the last keyframe.
Signal decode_hjif(std::string_view text, const SignalOptions& o, std::string_view origin) {
  if (o.region && !o.region->name.empty())
    throw FieldError("region",
                     "'" + o.region->name + "' is a name; a part of " + in_quotes(origin) + " is chosen as START:END in mm");
  hjif::ImportLimits limits;
  limits.max_keyframes = std::min<std::size_t>(limits.max_keyframes, o.max_samples);
  const hjif::Experience e = hjif::parse_hjif(text, origin, limits);
  const bool temporal = !e.perceptions.front().spatial;
  std::optional<MmPerSecond> v;
  if (temporal) v = need_speed(o, origin);
  std::optional<DeviceProfile> device = o.device;
  std::string grid_from = device ? "device " + device->name : std::string();
  if (!device && !o.spacing && e.carried) device = e.carried->device, grid_from = "its Texel document's device " + device->name;
  if (!device && !o.spacing && e.perceptions.front().reference_device) {
    const auto names = builtin_device_names();
    const std::string& name = *e.perceptions.front().reference_device;
    if (std::find(names.begin(), names.end(), name) != names.end())
      device = load_device(name), grid_from = "its reference device " + name;
  }
  Grid grid;
  if (device) {
    if (o.spacing) *device = with_grid(*device, std::nullopt, o.spacing);
    grid = device->grid();
  } else {
    double h = 0.0;
    if (o.spacing) {
      h = o.spacing->value(), grid_from = "spacing " + num(h) + " mm";
    } else if (temporal) {
      const double rate = e.perceptions.front().frequency_sampling.value_or(e.timescale);
      h = v->value() / rate, grid_from = num(rate) + " samples/s at " + num(v->value()) + " mm/s";
    } else {
      throw FieldError("device", "is required: " + in_quotes(origin) +
                                     " names no built-in device and carries no Texel document; give a device or a spacing "
                                     "to sample its curves on");
    }
    const double extent = hjif::extent_mm(e, v);
    const double n = std::floor(extent / h + 1e-9) + 1.0;
    if (!(n <= static_cast<double>(o.max_samples))) too_many(origin, static_cast<std::size_t>(std::min(n, 1e18)), o);
    grid = Grid{Millimetres(0.0), Millimetres(h), static_cast<std::int64_t>(n)};
  }
  if (grid.count > 0 && static_cast<std::uint64_t>(grid.count) > o.max_samples)
    too_many(origin, static_cast<std::size_t>(grid.count), o);
  std::vector<double> x(static_cast<std::size_t>(grid.count));
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = grid.position(static_cast<std::int64_t>(i)).value();
  Signal s;
  s.samples = hjif::evaluate(e, x, v);
  s.spacing = grid.spacing;
  s.origin = grid.origin;
  if (temporal) s.sample_rate = Hertz(v->value() / grid.spacing.value());  // scaled to full range, as recordings are
  s.description = "MPEG-I haptics: " + std::to_string(e.perceptions.size()) + " " + e.perceptions.front().modality +
                  (e.perceptions.size() == 1 ? " perception" : " perceptions") + " on " + grid_from;
  return s;
}

/// Keeps the samples whose positions lie in [start, end).
void apply_region(Signal& s, const SignalOptions::Region& r, std::string_view origin) {
  const double o = s.origin.value();
  const double h = s.spacing.value();
  const double last = o + h * static_cast<double>(s.samples.size());
  // First index with position >= start; one past the last with position < end
  // (a hundredth of a step of slack so a region ending on a sample excludes it).
  const double lo = std::ceil((r.start.value() - o) / h - 1e-9);
  const double hi = std::ceil((r.end.value() - o) / h - 1e-9);
  const auto first = static_cast<std::size_t>(std::clamp(lo, 0.0, static_cast<double>(s.samples.size())));
  const auto end = static_cast<std::size_t>(std::clamp(hi, 0.0, static_cast<double>(s.samples.size())));
  if (end <= first || end - first < 2)
    throw FieldError("region", "[" + num(r.start.value()) + ", " + num(r.end.value()) + ") mm holds " +
                                   std::to_string(end > first ? end - first : 0) + " samples of " + in_quotes(origin) +
                                   ", which spans [" + num(o) + ", " + num(last) + ") mm; a signal needs at least 2");
  s.samples = std::vector<double>(s.samples.begin() + static_cast<std::ptrdiff_t>(first),
                                  s.samples.begin() + static_cast<std::ptrdiff_t>(end));
  s.origin = Millimetres(o + h * static_cast<double>(first));
  if (r.name.empty()) s.description += ", region [" + num(r.start.value()) + ", " + num(r.end.value()) + ") mm";
}

/// What every format shares once its samples are known.
Signal finish(Signal s, SignalFormat format, const SignalOptions& o, std::string_view origin,
              const std::optional<SignalOptions::Region>& span) {
  s.format = format;
  if (s.samples.size() < 2) throw FormatError(in_quotes(origin) + " holds fewer than 2 samples");
  for (double v : s.samples)
    if (!std::isfinite(v)) throw FormatError(in_quotes(origin) + " holds a non-finite value");
  if (span)
    apply_region(s, *span, origin);
  else if (o.region && o.region->name.empty())
    apply_region(s, *o.region, origin);
  // Recordings, and maps outside [0, 1] (raw counts, signed data), are scaled to full range.
  const auto [lo, hi] = std::minmax_element(s.samples.begin(), s.samples.end());
  if (s.sample_rate || *lo < 0.0 || *hi > 1.0) {
    scale_full_range(s.samples, origin);
    s.scaled = true;
    if (!s.sample_rate) s.description += ", scaled to full range";
  }
  return s;
}

}  // namespace

bool to_amplitudes(std::span<double> values, std::string_view origin) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw FormatError(in_quotes(origin) + " holds a non-finite value (" + num(values[i]) + " at element " + std::to_string(i) +
                        ")");
  if (values.empty()) return false;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  if (*lo >= 0.0 && *hi <= 1.0) return false;
  scale_full_range(values, origin);
  return true;
}

std::string_view to_string(SignalFormat f) {
  switch (f) {
    case SignalFormat::device_map: return "device-map";
    case SignalFormat::npy: return "npy";
    case SignalFormat::csv: return "csv";
    case SignalFormat::wav: return "wav";
    case SignalFormat::mat: return "mat";
    case SignalFormat::document: return "document";
    case SignalFormat::bitstream: return "bitstream";
    case SignalFormat::hjif: return "hjif";
    case SignalFormat::hmpg: return "hmpg";
  }
  return "?";
}

SignalFormat signal_format_of(const std::string& path) {
  const std::string ext = output_extension(path);
  if (ext == ".bin") return SignalFormat::device_map;
  if (ext == ".npy") return SignalFormat::npy;
  if (ext == ".csv") return SignalFormat::csv;
  if (ext == ".wav") return SignalFormat::wav;
  if (ext == ".mat") return SignalFormat::mat;
  if (ext == ".texel.json" || ext == ".json") return SignalFormat::document;
  if (ext == ".texel") return SignalFormat::bitstream;
  if (ext == ".hjif") return SignalFormat::hjif;
  if (ext == ".hmpg") return SignalFormat::hmpg;
  throw InvalidArgument("input '" + path + "' has extension '" + ext +
                        "'; allowed: .bin (device map), .npy, .csv (position or time), .wav, .mat, .texel.json, .texel, .hjif, "
                        ".hmpg");
}

Recording decode_recording(std::span<const std::byte> bytes, const SignalOptions& o, std::string_view origin) {
  validate(o);
  Memory m{bytes};
  SF_VIRTUAL_IO io{mem_length, mem_seek, mem_read, mem_write, mem_tell};
  SF_INFO info{};
  SNDFILE* f = detail::sndfile().sf_open_virtual(&io, SFM_READ, &info, &m);
  if (!f)
    throw FormatError("cannot read " + in_quotes(origin) + " as audio: " + std::string(detail::sndfile().sf_strerror(nullptr)));
  return read_open(f, info, o, origin);
}

Recording read_recording(const std::string& path, const SignalOptions& o) {
  validate(o);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) (void)read_file(path);  // the IoError naming why
  SF_INFO info{};
  SNDFILE* f = detail::sndfile().sf_open(path.c_str(), SFM_READ, &info);
  if (!f)
    throw FormatError("cannot read " + in_quotes(path) + " as audio: " + std::string(detail::sndfile().sf_strerror(nullptr)));
  return read_open(f, info, o, path);
}

Signal decode_signal(std::span<const std::byte> bytes, SignalFormat format, const SignalOptions& o, std::string_view origin) {
  validate(o);
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  Signal s;
  std::optional<SignalOptions::Region> span;
  switch (format) {
    case SignalFormat::device_map: s = decode_device_map(bytes, o, origin); break;
    case SignalFormat::npy:
      // parse_npy allocates only after checking the data size against the
      // shape, so the array is never larger than the bytes given.
      s.samples = parse_npy(text, in_quotes(origin));
      if (s.samples.size() > o.max_samples) too_many(origin, s.samples.size(), o);
      s.spacing = device_spacing(o, origin, "(.npy)");
      s.description = ".npy at " + num(s.spacing.value()) + " mm";
      break;
    case SignalFormat::csv: s = decode_csv(text, o, origin); break;
    case SignalFormat::wav:
      need_speed(o, origin);  // before decoding anything
      s = from_recording(decode_recording(bytes, o, origin), o, origin);
      break;
    case SignalFormat::document: {
      s = render_document(parse_document(text, origin), o, origin, span);
      break;
    }
    case SignalFormat::hjif: s = decode_hjif(text, o, origin); break;
    case SignalFormat::hmpg: {
      hjif::ImportLimits limits;
      limits.max_keyframes = std::min<std::size_t>(limits.max_keyframes, o.max_samples);
      s = decode_hjif(hmpg::decode(bytes, origin, limits), o, origin);
      break;
    }
    case SignalFormat::mat:
      throw InvalidArgument(in_quotes(origin) + ": .mat maps are read from files only (libmatio opens by name)");
    case SignalFormat::bitstream:
      throw InvalidArgument(in_quotes(origin) + ": a bitstream (.texel) is decoded by the codec: codec::load_signal");
  }
  return finish(std::move(s), format, o, origin, span);
}

Signal signal_of_document(Document doc, const SignalOptions& o, std::string_view origin) {
  validate(o);
  std::optional<SignalOptions::Region> span;
  Signal s = render_document(std::move(doc), o, origin, span);
  return finish(std::move(s), SignalFormat::document, o, origin, span);
}

Signal load_signal(const std::string& path, const SignalOptions& o) {
  validate(o);
  const SignalFormat format = signal_format_of(path);
  if (format == SignalFormat::wav) {
    need_speed(o, path);  // before reading anything
    return finish(from_recording(read_recording(path, o), o, path), format, o, path, {});
  }
  if (format == SignalFormat::mat) {
    // The map variable and its grid (docs/format.md "MATLAB .mat"): the
    // file's spacing, else the explicit one, else the device's.
    mat::MapData m = mat::read_map(path, {.max_elements = o.max_samples});
    Signal s;
    s.samples = std::move(m.amplitude);
    if (m.spacing_mm) {
      check_spacing(*m.spacing_mm, o, path);
      s.spacing = Millimetres(*m.spacing_mm);
    } else {
      s.spacing = device_spacing(o, path, "(.mat without spacing_mm or position_mm)");
    }
    if (!m.position_mm.empty()) s.origin = Millimetres(m.position_mm.front());
    s.description = ".mat '" + m.variable + "' at " + num(s.spacing.value()) + " mm";
    return finish(std::move(s), format, o, path, {});
  }
  // Bound the read: no format stores a sample in fewer than one byte, and a
  // CSV row rarely takes more than 64.
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  const std::uintmax_t limit = format == SignalFormat::csv                                    ? o.max_samples * 64 + 4096
                               : format == SignalFormat::document                             ? std::uintmax_t{64} << 20
                               : format == SignalFormat::hjif || format == SignalFormat::hmpg ? std::uintmax_t{256} << 20
                                                                                              : o.max_samples * 8 + 65536;
  if (!ec && size > limit)
    throw FieldError("max_samples", "is " + std::to_string(o.max_samples) + "; " + in_quotes(path) + " has " +
                                        std::to_string(size) + " bytes, more than that many samples can take");
  const std::string bytes = read_file(path);
  return decode_signal(std::as_bytes(std::span(bytes.data(), bytes.size())), format, o, path);
}

}  // namespace texel
