#include "texel/bitstream.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "texel/detail/format.hpp"
#include "texel/distribution.hpp"
#include "texel/error.hpp"

namespace texel::codec {
namespace {

using detail::num;

// Flag bits of byte 2 (docs/format.md).
constexpr std::uint8_t flag_log = 1u << 0;
constexpr std::uint8_t flag_clamp = 1u << 1;
constexpr std::uint8_t flag_reset = 1u << 2;
constexpr std::uint8_t flag_partial = 1u << 3;
constexpr std::uint8_t flag_band_max_device = 1u << 4;
constexpr std::uint8_t flag_band_min = 1u << 5;
constexpr std::uint8_t flag_coarse = 1u << 6;
constexpr std::uint8_t flag_reserved = 1u << 7;

// Rice coding of the coarse residuals (JPEG-LS style adaptive parameter).
constexpr unsigned rice_escape = 24;  // unary quotients this long switch to raw bits
constexpr std::uint32_t rice_a0 = 2;  // initial sum of |residual|
constexpr std::uint32_t rice_reset = 32;

std::string hex(std::uint8_t b) {
  constexpr char d[] = "0123456789abcdef";
  return std::string("0x") + d[b >> 4] + d[b & 15];
}

// --- byte and bit writers ---------------------------------------------------

struct ByteWriter {
  std::vector<std::uint8_t> out;
  void u8(std::uint8_t v) { out.push_back(v); }
  void u16(std::uint16_t v) {
    out.push_back(static_cast<std::uint8_t>(v & 0xFF));
    out.push_back(static_cast<std::uint8_t>(v >> 8));
  }
  void i16(std::int16_t v) { u16(static_cast<std::uint16_t>(v)); }
  void varint(std::uint64_t v) {
    do {
      std::uint8_t b = v & 0x7F;
      v >>= 7;
      if (v) b |= 0x80;
      out.push_back(b);
    } while (v);
  }
};

struct BitWriter {
  std::vector<std::uint8_t>& out;
  std::uint32_t acc = 0;
  int used = 0;  // bits in acc, MSB first
  void bit(unsigned b) {
    acc = (acc << 1) | (b & 1u);
    if (++used == 8) {
      out.push_back(static_cast<std::uint8_t>(acc));
      acc = 0;
      used = 0;
    }
  }
  void bits(std::uint32_t v, unsigned n) {
    for (unsigned i = n; i-- > 0;) bit((v >> i) & 1u);
  }
  void flush() {
    while (used) bit(0);
  }
};

// --- readers (bounds-checked; every failure names the field) ----------------

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> b) : b_(b) {}
  [[nodiscard]] std::size_t offset() const { return pos_; }
  [[nodiscard]] std::size_t remaining() const { return b_.size() - pos_; }
  std::uint8_t u8(const char* field) {
    need(1, field);
    return b_[pos_++];
  }
  std::uint16_t u16(const char* field) {
    need(2, field);
    const auto v = static_cast<std::uint16_t>(b_[pos_] | (b_[pos_ + 1] << 8));
    pos_ += 2;
    return v;
  }
  std::int16_t i16(const char* field) { return static_cast<std::int16_t>(u16(field)); }
  std::uint64_t varint(const char* field) {
    std::uint64_t v = 0;
    for (unsigned i = 0; i < 10; ++i) {
      const std::size_t at = pos_;
      const std::uint8_t b = u8(field);
      if (i == 9 && b > 1)
        throw FormatError(std::string("bitstream field '") + field + "' at byte " + std::to_string(at) +
                          " overflows 64 bits; allowed: a LEB128 varint of at most 64 bits");
      v |= static_cast<std::uint64_t>(b & 0x7F) << (7 * i);
      if (!(b & 0x80)) {
        if (b == 0 && i > 0)
          throw FormatError(std::string("bitstream field '") + field + "' at byte " + std::to_string(at) +
                            " is a non-canonical varint (a trailing zero byte); allowed: shortest encoding");
        return v;
      }
    }
    throw FormatError(std::string("bitstream field '") + field + "' is a varint longer than 10 bytes");
  }
  std::span<const std::uint8_t> rest() const { return b_.subspan(pos_); }
  void skip(std::size_t n) { pos_ += n; }

 private:
  void need(std::size_t n, const char* field) const {
    if (remaining() < n)
      throw FormatError(std::string("bitstream truncated: field '") + field + "' needs " + std::to_string(n) +
                        " byte(s) at offset " + std::to_string(pos_) + ", " + std::to_string(remaining()) +
                        " left before the CRC");
  }
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
};

class BitReader {
 public:
  explicit BitReader(std::span<const std::uint8_t> b) : b_(b) {}
  unsigned bit() {
    if (pos_ >= b_.size() * 8)
      throw FormatError("bitstream truncated: the coarse levels need more bits than the " + std::to_string(b_.size()) +
                        " byte(s) before the CRC");
    const unsigned v = (b_[pos_ >> 3] >> (7 - (pos_ & 7))) & 1u;
    ++pos_;
    return v;
  }
  std::uint32_t bits(unsigned n) {
    std::uint32_t v = 0;
    for (unsigned i = 0; i < n; ++i) v = (v << 1) | bit();
    return v;
  }
  [[nodiscard]] std::size_t bytes_used() const { return (pos_ + 7) / 8; }
  [[nodiscard]] bool padding_is_zero() const {
    const std::size_t rem = pos_ & 7;
    if (rem == 0) return true;
    return (b_[pos_ >> 3] & ((1u << (8 - rem)) - 1u)) == 0;
  }

 private:
  std::span<const std::uint8_t> b_;
  std::size_t pos_ = 0;
};

// --- coarse levels: prediction, wrap, zigzag, adaptive Rice -----------------

struct RiceState {
  std::uint32_t a = rice_a0;
  std::uint32_t n = 1;
  [[nodiscard]] unsigned k() const {
    unsigned k = 0;
    while ((n << k) < a && k < 16) ++k;
    return k;
  }
  void update(std::uint32_t u) {
    a += u;
    if (++n == rice_reset) {
      a = (a + 1) >> 1;
      n >>= 1;
    }
  }
};

std::int64_t predict(const std::vector<std::uint16_t>& q, std::size_t k, unsigned predictor, unsigned bits) {
  const std::int64_t top = (std::int64_t{1} << bits) - 1;
  const std::int64_t mid = std::int64_t{1} << (bits - 1);
  if (k == 0 || predictor == 0) return mid;
  if (predictor == 1 || k == 1) return q[k - 1];
  const std::int64_t p = 2 * static_cast<std::int64_t>(q[k - 1]) - q[k - 2];
  return std::clamp<std::int64_t>(p, 0, top);
}

std::uint32_t residual_code(std::int64_t value, std::int64_t prediction, unsigned bits) {
  const std::int64_t m = std::int64_t{1} << bits;
  std::int64_t e = (value - prediction) & (m - 1);  // mod 2^bits
  if (e >= m / 2) e -= m;                           // [-2^(b-1), 2^(b-1))
  return static_cast<std::uint32_t>(e >= 0 ? 2 * e : -2 * e - 1);
}

std::uint16_t apply_residual(std::uint32_t u, std::int64_t prediction, unsigned bits) {
  const std::int64_t m = std::int64_t{1} << bits;
  const std::int64_t e = (u & 1u) ? -static_cast<std::int64_t>((u + 1) / 2) : static_cast<std::int64_t>(u / 2);
  return static_cast<std::uint16_t>((prediction + e) & (m - 1));
}

void write_levels(BitWriter& w, const CoarseFields& c) {
  RiceState rs;
  for (std::size_t k = 0; k < c.levels.size(); ++k) {
    const std::uint32_t u = residual_code(c.levels[k], predict(c.levels, k, c.predictor, c.bits), c.bits);
    const unsigned kk = rs.k();
    const std::uint32_t quotient = u >> kk;
    if (quotient < rice_escape) {
      for (std::uint32_t i = 0; i < quotient; ++i) w.bit(1);
      w.bit(0);
      w.bits(u & ((1u << kk) - 1u), kk);
    } else {
      for (unsigned i = 0; i < rice_escape; ++i) w.bit(1);
      w.bits(u, c.bits);
    }
    rs.update(u);
  }
  w.flush();
}

void check_range(double v, double lo, double hi, const std::string& field, const std::string& allowed) {
  if (!(v >= lo && v <= hi)) throw InvalidArgument(field + " is " + num(v) + "; the bitstream allows " + allowed);
}

std::int16_t to_cdb(double db, const std::string& field) {
  const double n = std::round(db * 100.0);
  check_range(n, -32768.0, 32767.0, field, "-327.68 … 327.67 dB");
  return static_cast<std::int16_t>(n);
}

}  // namespace

std::uint8_t crc8(std::span<const std::byte> bytes) {
  std::uint8_t crc = 0;
  for (const std::byte b : bytes) {
    crc ^= std::to_integer<std::uint8_t>(b);
    for (int i = 0; i < 8; ++i) crc = static_cast<std::uint8_t>((crc & 0x80) ? (crc << 1) ^ 0x07 : crc << 1);
  }
  return crc;
}

std::vector<std::byte> write_bitstream(const Bitstream& b) {
  const FineFields& f = b.fine;
  if (f.texel_length_um == 0) throw InvalidArgument("texel_length_um is 0; the bitstream allows 1 … 65535 µm");
  if (f.quantization_ddb > 200)
    throw InvalidArgument("quantization is " + num(f.quantization_ddb / 10.0) + " dB; the bitstream allows 0 … 20 dB");
  ByteWriter w;
  w.u8(bitstream_magic);
  w.u8(bitstream_version);
  std::uint8_t flags = 0;
  if (f.parameterization == Parameterization::log) flags |= flag_log;
  if (f.out_of_band == OutOfBand::clamp) flags |= flag_clamp;
  if (f.phase == PhaseMode::reset) flags |= flag_reset;
  if (f.fill == Fill::partial_final_texel) flags |= flag_partial;
  if (f.band_max_device) flags |= flag_band_max_device;
  if (f.band_min_cdb) flags |= flag_band_min;
  if (b.coarse) flags |= flag_coarse;
  w.u8(flags);
  w.i16(f.central_pitch_cdb);
  w.i16(f.irregularity_cdb);
  w.u16(f.texel_length_um);
  w.u8(f.quantization_ddb);
  if (!f.band_max_device) w.i16(f.band_max_cdb);
  if (f.band_min_cdb) w.i16(*f.band_min_cdb);
  w.varint(f.seed);
  if (b.coarse) {
    const CoarseFields& c = *b.coarse;
    if (c.bits > 16) throw InvalidArgument("coarse bits is " + std::to_string(c.bits) + "; the bitstream allows 0 … 16");
    if (c.predictor > 2) throw InvalidArgument("coarse predictor is " + std::to_string(c.predictor) + "; allowed: 0, 1, 2");
    w.u8(c.coarse_strength);
    w.u8(c.fine_strength);
    w.u8(static_cast<std::uint8_t>(c.bits | (c.predictor << 5)));
    if (c.bits > 0) {
      if (c.stride == 0) throw InvalidArgument("coarse stride is 0; allowed: >= 1 texel");
      if (c.levels.empty() || c.levels.size() > max_coarse_levels)
        throw InvalidArgument("coarse profile has " + std::to_string(c.levels.size()) + " levels; allowed: 1 … " +
                              std::to_string(max_coarse_levels));
      const std::uint32_t top = (1u << c.bits) - 1u;
      for (std::size_t k = 0; k < c.levels.size(); ++k)
        if (c.levels[k] > top)
          throw InvalidArgument("coarse level " + std::to_string(k) + " is " + std::to_string(c.levels[k]) + "; with " +
                                std::to_string(c.bits) + " bits allowed: 0 … " + std::to_string(top));
      w.varint(c.stride);
      w.varint(c.levels.size());
      BitWriter bw{w.out};
      write_levels(bw, c);
    }
  }
  std::vector<std::byte> out(w.out.size() + 1);
  std::transform(w.out.begin(), w.out.end(), out.begin(), [](std::uint8_t v) { return std::byte{v}; });
  out.back() = std::byte{crc8(std::span<const std::byte>(out).first(w.out.size()))};
  return out;
}

Bitstream parse_bitstream(std::span<const std::byte> input) {
  // The readers work on octets; unsigned char may alias any object.
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(input.data()), input.size());
  if (bytes.empty()) throw FormatError("bitstream is empty; a .texel bitstream is at least 12 bytes");
  if (bytes[0] != bitstream_magic)
    throw FormatError("not a Texel bitstream: first byte is " + hex(bytes[0]) + ", expected " + hex(bitstream_magic) + " ('T')");
  if (bytes.size() < 2) throw FormatError("bitstream truncated: 1 byte, no version");
  if (bytes[1] != bitstream_version)
    throw FormatError("unsupported bitstream version " + std::to_string(bytes[1]) + "; this build reads version " +
                      std::to_string(bitstream_version));
  if (bytes.size() < 12)
    throw FormatError("bitstream truncated: " + std::to_string(bytes.size()) + " bytes; a version-1 bitstream has at least 12");
  ByteReader r(bytes.first(bytes.size() - 1));  // the last byte is the CRC
  r.skip(2);
  Bitstream b;
  FineFields& f = b.fine;
  const std::uint8_t flags = r.u8("flags");
  if (flags & flag_reserved) throw FormatError("bitstream flags " + hex(flags) + " set reserved bit 7; allowed: 0");
  f.parameterization = (flags & flag_log) ? Parameterization::log : Parameterization::moments;
  f.out_of_band = (flags & flag_clamp) ? OutOfBand::clamp : OutOfBand::redraw;
  f.phase = (flags & flag_reset) ? PhaseMode::reset : PhaseMode::continuous;
  f.fill = (flags & flag_partial) ? Fill::partial_final_texel : Fill::whole_texels;
  f.band_max_device = (flags & flag_band_max_device) != 0;
  f.central_pitch_cdb = r.i16("central_pitch");
  f.irregularity_cdb = r.i16("irregularity");
  f.texel_length_um = r.u16("texel_length");
  if (f.texel_length_um == 0) throw FormatError("bitstream texel_length is 0 µm; allowed: 1 … 65535 µm");
  f.quantization_ddb = r.u8("quantization");
  if (f.quantization_ddb > 200)
    throw FormatError("bitstream quantization is " + num(f.quantization_ddb / 10.0) + " dB; allowed: 0 … 20 dB");
  if (!f.band_max_device) f.band_max_cdb = r.i16("band_max");
  if (flags & flag_band_min) f.band_min_cdb = r.i16("band_min");
  f.seed = r.varint("seed");
  if (flags & flag_coarse) {
    CoarseFields c;
    c.coarse_strength = r.u8("coarse_strength");
    c.fine_strength = r.u8("fine_strength");
    const std::uint8_t mode = r.u8("coarse_mode");
    c.bits = mode & 0x1F;
    c.predictor = (mode >> 5) & 0x3;
    if (mode & 0x80) throw FormatError("bitstream coarse_mode " + hex(mode) + " sets reserved bit 7; allowed: 0");
    if (c.bits > 16) throw FormatError("bitstream coarse bits is " + std::to_string(c.bits) + "; allowed: 0 … 16");
    if (c.predictor > 2) throw FormatError("bitstream coarse predictor is " + std::to_string(c.predictor) + "; allowed: 0, 1, 2");
    if (c.bits > 0) {
      const std::uint64_t stride = r.varint("coarse_stride");
      if (stride == 0 || stride > max_coarse_levels)
        throw FormatError("bitstream coarse_stride is " + std::to_string(stride) + "; allowed: 1 … " +
                          std::to_string(max_coarse_levels));
      c.stride = static_cast<std::uint32_t>(stride);
      const std::uint64_t count = r.varint("coarse_count");
      // Every level costs at least one bit, so the bytes present bound the count.
      if (count == 0 || count > max_coarse_levels || count > 8 * static_cast<std::uint64_t>(r.remaining()))
        throw FormatError("bitstream coarse_count is " + std::to_string(count) + "; allowed: 1 … " +
                          std::to_string(std::min<std::uint64_t>(max_coarse_levels, 8 * r.remaining())) +
                          " (at most one level per bit present)");
      c.levels.resize(static_cast<std::size_t>(count));
      BitReader br(r.rest());
      RiceState rs;
      for (std::size_t k = 0; k < c.levels.size(); ++k) {
        const unsigned kk = rs.k();
        unsigned quotient = 0;
        while (quotient < rice_escape && br.bit()) ++quotient;
        std::uint32_t u;
        if (quotient == rice_escape) {
          u = br.bits(c.bits);
          if ((u >> kk) < rice_escape)
            throw FormatError("bitstream coarse level " + std::to_string(k) + " uses an escape for residual code " +
                              std::to_string(u) + ", which has a short code; allowed: canonical Rice codes only");
        } else {
          u = (quotient << kk) | br.bits(kk);
          if (u >= (1u << c.bits))
            throw FormatError("bitstream coarse level " + std::to_string(k) + " has residual code " + std::to_string(u) +
                              "; with " + std::to_string(c.bits) + " bits allowed: 0 … " + std::to_string((1u << c.bits) - 1));
        }
        c.levels[k] = apply_residual(u, predict(c.levels, k, c.predictor, c.bits), c.bits);
        rs.update(u);
      }
      if (!br.padding_is_zero()) throw FormatError("bitstream coarse levels end with non-zero padding bits; allowed: 0");
      r.skip(br.bytes_used());
    }
    b.coarse = std::move(c);
  }
  if (r.remaining() != 0)
    throw FormatError("bitstream oversized: " + std::to_string(r.remaining()) + " unexpected byte(s) at offset " +
                      std::to_string(r.offset()) + " before the CRC");
  const std::uint8_t want = crc8(input.first(input.size() - 1));
  if (bytes.back() != want)
    throw FormatError("bitstream CRC mismatch: stored " + hex(bytes.back()) + ", computed " + hex(want) +
                      " (corrupted or truncated)");

  // The texture must be renderable: validate the spec and its distribution.
  try {
    const TexelSpec spec = to_spec(b);
    validate(spec);
    PitchDistributionConfig pc;
    pc.central_pitch = spec.central_pitch;
    pc.irregularity = spec.irregularity;
    pc.parameterization = spec.parameterization;
    pc.out_of_band = spec.out_of_band;
    pc.band_min = spec.band_min;
    // A device-dependent band is checked against the widest band allowed.
    pc.band_max = spec.band_max.value() > 0 ? spec.band_max : CyclesPerMm(1e4);
    pc.quantization_db = spec.quantization_db;
    (void)PitchDistribution(pc);
  } catch (const InvalidArgument& e) {
    throw FormatError(std::string("bitstream describes an unrenderable texture: ") + e.what());
  }
  return b;
}

TexelSpec to_spec(const Bitstream& b) {
  const FineFields& f = b.fine;
  TexelSpec s;
  s.central_pitch = Decibels(f.central_pitch_cdb / 100.0);
  s.irregularity = Decibels(f.irregularity_cdb / 100.0);
  s.texel_length = Millimetres(f.texel_length_um / 1000.0);
  s.seed = f.seed;
  s.parameterization = f.parameterization;
  s.out_of_band = f.out_of_band;
  s.band_min = f.band_min_cdb ? to_cpm(Decibels(*f.band_min_cdb / 100.0)) : CyclesPerMm(0.01);
  s.band_max = f.band_max_device ? CyclesPerMm(0.0) : to_cpm(Decibels(f.band_max_cdb / 100.0));
  s.quantization_db = f.quantization_ddb / 10.0;
  s.phase = f.phase;
  s.fill = f.fill;
  if (!b.coarse) {
    s.coarse_strength = 0.0;
    s.fine_strength = 1.0;
    s.coarse = ConstantProfile{1.0};
    return s;
  }
  const CoarseFields& c = *b.coarse;
  s.coarse_strength = c.coarse_strength / 255.0;
  s.fine_strength = c.fine_strength / 255.0;
  if (c.bits == 0) {
    s.coarse = ConstantProfile{0.0};
    return s;
  }
  const double top = static_cast<double>((1u << c.bits) - 1u);
  const double L = s.texel_length.value();
  PointsProfile p;
  p.points.reserve(c.levels.size());
  for (std::size_t j = 0; j < c.levels.size(); ++j) {
    // The same expression as the texel centre in sample_at_texel_centres, so
    // texel j·stride samples its level exactly.
    const double x = (static_cast<double>(j * static_cast<std::size_t>(c.stride)) + 0.5) * L;
    p.points.emplace_back(x, c.levels[j] / top);
  }
  s.coarse = std::move(p);
  return s;
}

Bitstream from_spec(const TexelSpec& spec, Millimetres length, unsigned bits) {
  validate(spec);
  if (bits < 1 || bits > 16) throw InvalidArgument("coarse bits is " + std::to_string(bits) + "; allowed: 1 … 16");
  Bitstream b;
  FineFields& f = b.fine;
  f.central_pitch_cdb = to_cdb(spec.central_pitch.value(), "central_pitch_db");
  f.irregularity_cdb = to_cdb(spec.irregularity.value(), "irregularity_db");
  const double um = std::round(spec.texel_length.value() * 1000.0);
  check_range(um, 1.0, 65535.0, "texel_length_mm " + num(spec.texel_length.value()), "0.001 … 65.535 mm");
  f.texel_length_um = static_cast<std::uint16_t>(um);
  const double q = std::round(spec.quantization_db * 10.0);
  check_range(q, 0.0, 200.0, "quantization_db", "0 … 20 dB in 0.1 dB steps");
  f.quantization_ddb = static_cast<std::uint8_t>(q);
  f.band_max_device = spec.band_max.value() == 0.0;
  // Round the band top down so the stored band never exceeds the one given.
  if (!f.band_max_device) f.band_max_cdb = static_cast<std::int16_t>(std::floor(to_db(spec.band_max).value() * 100.0 + 1e-9));
  if (spec.band_min.value() != 0.01) f.band_min_cdb = to_cdb(to_db(spec.band_min).value(), "band_min_db");
  f.seed = spec.seed;
  f.parameterization = spec.parameterization;
  f.out_of_band = spec.out_of_band;
  f.phase = spec.phase;
  f.fill = spec.fill;

  const double C = spec.coarse_strength;
  const double F = spec.fine_strength;
  const auto* constant = std::get_if<ConstantProfile>(&spec.coarse);
  if (C == 0.0 || (constant && constant->value == 1.0)) {
    if (F == 1.0) return b;  // e_k = 1 everywhere: fine only
  }
  CoarseFields c;
  c.fine_strength = static_cast<std::uint8_t>(std::lround(F * 255.0));
  if (constant || C == 0.0) {
    // e = 1 − C(1 − v) is a constant: fold it into C with c = 0.
    const double eff = constant ? C * (1.0 - constant->value) : 0.0;
    c.coarse_strength = static_cast<std::uint8_t>(std::lround(eff * 255.0));
    c.bits = 0;
  } else {
    c.coarse_strength = static_cast<std::uint8_t>(std::lround(C * 255.0));
    const std::size_t n = std::max<std::size_t>(1, texel_count(length, spec.texel_length, spec.fill));
    if (n > max_coarse_levels)
      throw InvalidArgument("coarse profile of " + std::to_string(n) + " texels exceeds the bitstream's limit");
    const std::vector<double> v = sample_at_texel_centres(spec.coarse, spec.texel_length, n);
    const double top = static_cast<double>((1u << bits) - 1u);
    c.bits = static_cast<std::uint8_t>(bits);
    c.levels.resize(n);
    for (std::size_t k = 0; k < n; ++k) c.levels[k] = static_cast<std::uint16_t>(std::lround(v[k] * top));
  }
  b.coarse = std::move(c);
  return b;
}

std::size_t coarse_section_bytes(const CoarseFields& c) {
  Bitstream b;
  b.coarse = c;
  Bitstream fine_only;
  return write_bitstream(b).size() - write_bitstream(fine_only).size();
}

}  // namespace texel::codec
