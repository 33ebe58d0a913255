// Loading texture signals for the encoder, and the zstd figure of the
// compression report.
#include <sndfile.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "texel/codec.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/matfile.hpp"

namespace texel::codec {
namespace {

using detail::num;

/// A time recording becomes a full-range texture: a = 0.5 + 0.5·y/max|y|
/// (the references' scaling, references.md), y the zero-mean recording.
void normalize_full_range(std::vector<double>& y, const std::string& path) {
  double mean = 0.0;
  for (double v : y) mean += v;
  mean /= static_cast<double>(y.size());
  double peak = 0.0;
  for (double& v : y) v -= mean, peak = std::max(peak, std::fabs(v));
  if (!(peak > 0.0)) throw InvalidArgument("'" + path + "' is constant: it holds no texture to encode");
  for (double& v : y) v = 0.5 + 0.5 * v / peak;
}

MmPerSecond need_speed(const LoadOptions& o, const std::string& path) {
  if (!o.swipe_speed)
    throw InvalidArgument("'" + path +
                          "' is a time recording; give the swipe speed that turns time into position (--swipe-speed MM_S)");
  return *o.swipe_speed;
}

/// Spacing of a sampled axis; it must be uniform within 1 % of a step.
double uniform_step(const std::vector<double>& axis, const std::string& path, const char* what) {
  if (axis.size() < 2) throw FormatError("'" + path + "' has fewer than 2 rows");
  const double step = (axis.back() - axis.front()) / static_cast<double>(axis.size() - 1);
  if (!(step > 0.0 && std::isfinite(step)))
    throw FormatError("'" + path + "': the " + std::string(what) + " column must increase");
  for (std::size_t i = 1; i < axis.size(); ++i)
    if (std::fabs(axis[i] - axis[i - 1] - step) > 0.01 * step)
      throw FormatError("'" + path + "': the " + std::string(what) + " column is not uniformly sampled at row " +
                        std::to_string(i + 1) + " (step " + num(axis[i] - axis[i - 1]) + ", expected " + num(step) + ")");
  return step;
}

Signal load_wav(const std::string& path, const LoadOptions& o) {
  const MmPerSecond v = need_speed(o, path);
  SF_INFO info{};
  SNDFILE* f = sf_open(path.c_str(), SFM_READ, &info);
  if (!f) throw FormatError("cannot read '" + path + "' as audio: " + std::string(sf_strerror(nullptr)));
  struct Closer {
    SNDFILE* f;
    ~Closer() { sf_close(f); }
  } closer{f};
  if (info.frames <= 0 || info.channels <= 0 || info.samplerate <= 0) throw FormatError("'" + path + "' holds no audio frames");
  if (info.frames > (std::int64_t{1} << 28)) throw InvalidArgument("'" + path + "' is too long (more than 2^28 frames)");
  std::vector<double> inter(static_cast<std::size_t>(info.frames) * static_cast<std::size_t>(info.channels));
  const sf_count_t got = sf_readf_double(f, inter.data(), info.frames);
  std::vector<double> y(static_cast<std::size_t>(got));
  for (std::size_t i = 0; i < y.size(); ++i) {
    double s = 0.0;
    for (int c = 0; c < info.channels; ++c) s += inter[i * static_cast<std::size_t>(info.channels) + static_cast<std::size_t>(c)];
    y[i] = s / info.channels;  // channels mixed to mono
  }
  normalize_full_range(y, path);
  Signal sig;
  sig.amplitude = std::move(y);
  sig.spacing = Millimetres(v.value() / info.samplerate);
  sig.description = "audio " + std::to_string(info.samplerate) + " Hz at " + num(v.value()) + " mm/s";
  return sig;
}

Signal load_csv(const std::string& path, const LoadOptions& o) {
  const std::string text = read_file(path);
  auto [x, y] = parse_csv_columns(text, path);
  // A header whose first column starts with 't' ("time", "t_s") marks a recording.
  const auto first = text.find_first_not_of(" \t\r\n");
  const bool is_time = first != std::string::npos && (text[first] == 't' || text[first] == 'T');
  Signal sig;
  if (is_time) {
    const MmPerSecond v = need_speed(o, path);
    const double dt = uniform_step(x, path, "time");
    normalize_full_range(y, path);
    sig.spacing = Millimetres(v.value() * dt);
    sig.description = "time/value CSV at " + num(v.value()) + " mm/s";
  } else {
    sig.spacing = Millimetres(uniform_step(x, path, "position"));
    sig.description = "position/amplitude CSV";
  }
  sig.amplitude = std::move(y);
  return sig;
}

double device_spacing(const LoadOptions& o, const DeviceProfile& d) { return (o.spacing ? *o.spacing : d.spacing).value(); }

}  // namespace

Signal load_signal(const std::string& path, const LoadOptions& o) {
  const std::string ext = output_extension(path);
  const DeviceProfile device = o.device ? *o.device : load_device("tpad");
  if (o.spacing && !(std::isfinite(o.spacing->value()) && o.spacing->value() > 0))
    throw InvalidArgument("--spacing is " + num(o.spacing->value()) + "; it must be a finite number of mm > 0");
  Signal sig;
  if (ext == ".bin") {
    const std::string bytes = read_file(path);
    const std::size_t bps = bytes_per_sample(device.format);
    if (bytes.empty() || bytes.size() % bps != 0)
      throw FormatError("'" + path + "' has " + std::to_string(bytes.size()) + " bytes, not a whole number of " +
                        std::string(to_string(device.format)) + " samples of device '" + device.name +
                        "' (choose it with --device)");
    sig.amplitude = decode_samples(device.format, std::span(reinterpret_cast<const std::byte*>(bytes.data()), bytes.size()));
    sig.spacing = Millimetres(device_spacing(o, device));
    sig.description = "device map (" + device.name + ", " + std::string(to_string(device.format)) + ")";
  } else if (ext == ".npy") {
    sig.amplitude = parse_npy(read_file(path), path);
    sig.spacing = Millimetres(device_spacing(o, device));
    sig.description = ".npy at " + num(sig.spacing.value()) + " mm";
  } else if (ext == ".mat") {
    // The map variable and its grid (docs/format.md "MATLAB .mat"); an
    // explicit spacing wins over the file's, the file's over the device's.
    mat::MapData m = mat::read_map(path);
    sig.amplitude = std::move(m.amplitude);
    sig.spacing = Millimetres(o.spacing ? o.spacing->value() : m.spacing_mm ? *m.spacing_mm : device.spacing.value());
    sig.description = ".mat '" + m.variable + "' at " + num(sig.spacing.value()) + " mm" +
                      (o.spacing || m.spacing_mm ? "" : " (device " + device.name + ")");
  } else if (ext == ".csv") {
    sig = load_csv(path, o);
  } else if (ext == ".wav") {
    sig = load_wav(path, o);
  } else if (ext == ".texel.json") {
    const Document doc = load_document(path);
    sig.amplitude = prepare_surface(doc).render();
    sig.spacing = Millimetres(doc.device.spacing.value());
    sig.description = "document on " + doc.device.name;
  } else if (ext == ".texel") {
    const std::string bytes = read_file(path);
    const Bitstream b = parse_bitstream(byte_view(bytes));
    sig.amplitude = prepare_surface(decode_document(b, device)).render();
    sig.spacing = device.spacing;
    sig.description = "bitstream decoded on " + device.name;
  } else {
    throw InvalidArgument("input '" + path + "' has extension '" + ext +
                          "'; allowed: .bin (device map), .npy, .mat, .csv (position or time), .wav, .texel.json, .texel");
  }
  if (sig.amplitude.size() < 2) throw FormatError("'" + path + "' holds fewer than 2 samples");
  for (double v : sig.amplitude)
    if (!std::isfinite(v)) throw FormatError("'" + path + "' holds a non-finite value");
  // Spatial maps outside [0, 1] (raw counts, signed data) are scaled like recordings.
  const auto [lo, hi] = std::minmax_element(sig.amplitude.begin(), sig.amplitude.end());
  if (*lo < 0.0 || *hi > 1.0) {
    normalize_full_range(sig.amplitude, path);
    sig.description += ", scaled to full range";
  }
  return sig;
}

std::size_t zstd_size(std::span<const std::byte> bytes) {
  std::vector<char> out(ZSTD_compressBound(bytes.size()));
  ZSTD_CCtx* ctx = ZSTD_createCCtx();
  if (!ctx) throw IoError("zstd: cannot create a compression context");
  ZSTD_CCtx_setParameter(ctx, ZSTD_c_compressionLevel, ZSTD_maxCLevel());
  const std::size_t r = ZSTD_compress2(ctx, out.data(), out.size(), bytes.data(), bytes.size());
  ZSTD_freeCCtx(ctx);
  if (ZSTD_isError(r)) throw IoError(std::string("zstd: ") + ZSTD_getErrorName(r));
  return r;
}

}  // namespace texel::codec
