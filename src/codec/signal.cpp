// Loading texture signals for the encoder, and the zstd figure of the
// compression report.
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "texel/codec.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/matfile.hpp"

namespace texel::codec {

texel::Signal decode_signal(std::span<const std::byte> bytes, SignalFormat format, const SignalOptions& o,
                            std::string_view origin) {
  if (format != SignalFormat::bitstream) return texel::decode_signal(bytes, format, o, origin);
  if (!o.device)
    throw FieldError("device", "is required: '" + std::string(origin) +
                                   "' is a bitstream (.texel), which describes a texture, not a grid to render it on");
  const Bitstream b = parse_bitstream(bytes);
  texel::Signal s = signal_of_document(decode_document(b, *o.device), o, origin);
  s.format = SignalFormat::bitstream;
  s.description = "bitstream decoded on " + o.device->name;
  return s;
}

namespace {
// A bitstream file's bytes: a few bytes, so anything past 1 MiB is not one
// (checked before reading).
std::string bitstream_file_bytes(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > (std::uintmax_t{1} << 20))
    throw FormatError("'" + path + "' has " + std::to_string(size) + " bytes; a bitstream is at most 1 MiB");
  return read_file(path);
}
}  // namespace

texel::Signal load_signal(const std::string& path, const SignalOptions& o) {
  if (signal_format_of(path) != SignalFormat::bitstream) return texel::load_signal(path, o);
  const std::string bytes = bitstream_file_bytes(path);
  return codec::decode_signal(std::as_bytes(std::span(bytes.data(), bytes.size())), SignalFormat::bitstream, o, path);
}

Bitstream read_bitstream(const std::string& path) {
  const std::string bytes = bitstream_file_bytes(path);
  return parse_bitstream(std::as_bytes(std::span(bytes.data(), bytes.size())));
}

std::array<std::pair<const char*, double>, 6> fields(const Percept& p) {
  return {{{"pitch_db", p.pitch_db},
           {"noisiness_db", p.noisiness_db},
           {"centroid_db", p.mean_db},
           {"spread_db", p.spread_db},
           {"drawn_pitch_db", p.drawn_pitch_db},
           {"drawn_noisiness_db", p.drawn_noisiness_db}}};
}

Signal encoder_signal(const texel::Signal& s) { return Signal{s.samples, s.spacing, s.description, s.sample_rate.has_value()}; }

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
