// The .texel bitstream (docs/format.md, "Bitstream (.texel)"): sizes, every
// field round-tripping, exact decoding to the spec and to rendered bytes,
// device independence, and every class of bad input rejected with a
// FormatError (never a crash).
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "../support/expect.hpp"
#include "texel/bitstream.hpp"
#include "texel/codec.hpp"
#include "texel/error.hpp"

namespace {

using namespace texel;
using namespace texel::codec;

Bitstream coarse_example(unsigned bits, std::uint8_t predictor, std::uint32_t stride, std::size_t count) {
  Bitstream b;
  b.fine.central_pitch_cdb = 1000;
  b.fine.irregularity_cdb = -500;
  CoarseFields c;
  c.coarse_strength = 153;
  c.fine_strength = 128;
  c.bits = static_cast<std::uint8_t>(bits);
  c.predictor = predictor;
  c.stride = stride;
  const std::uint32_t top = (1u << bits) - 1u;
  for (std::size_t k = 0; k < count; ++k)  // a smooth profile with a jump
    c.levels.push_back(static_cast<std::uint16_t>(k < count / 2 ? (k * top) / count : top - (k % 7)));
  b.coarse = c;
  return b;
}

std::vector<std::byte> bytes_of(std::initializer_list<unsigned> octets) {
  std::vector<std::byte> out;
  for (unsigned o : octets) out.push_back(static_cast<std::byte>(o));
  return out;
}

std::string message_of(const std::vector<std::byte>& bytes) {
  return texel::test_support::message_of<FormatError>([&] { (void)parse_bitstream(bytes); });
}

TEST(Bitstream, FineOnlyFitsIn16Bytes) {
  Bitstream b;
  EXPECT_EQ(write_bitstream(b).size(), 14u);  // seed < 128
  b.fine.seed = (1u << 21) - 1;
  EXPECT_EQ(write_bitstream(b).size(), 16u);  // seed < 2^21: still 16
  b.fine.seed = ~0ULL;
  EXPECT_EQ(write_bitstream(b).size(), 23u);  // a full 64-bit seed: documented 23 bytes
}

TEST(Bitstream, GoldenBytesOfTheDefaultStream) {
  // 'T', version 1, flags 0, P 1000 cdB, I -500 cdB, L 250 µm, q 0, band top 1974 cdB, seed 1, CRC.
  const std::vector<std::byte> want = bytes_of({0x54, 0x01, 0x00, 0xE8, 0x03, 0x0C, 0xFE, 0xFA, 0x00, 0x00, 0xB6, 0x07, 0x01});
  auto got = write_bitstream(Bitstream{});
  ASSERT_EQ(got.size(), 14u);
  EXPECT_EQ(std::vector<std::byte>(got.begin(), got.end() - 1), want);
  EXPECT_EQ(got.back(), std::byte{crc8(want)});
}

TEST(Bitstream, Crc8CheckValue) {
  const std::string s = "123456789";  // the CRC-8/SMBUS check value
  EXPECT_EQ(crc8(std::as_bytes(std::span(s.data(), s.size()))), 0xF4);
}

RC_GTEST_PROP(Bitstream, EveryFineFieldRoundTrips, ()) {
  Bitstream b;
  FineFields& f = b.fine;
  f.parameterization = *rc::gen::element(Parameterization::moments, Parameterization::log);
  f.central_pitch_cdb = static_cast<std::int16_t>(*rc::gen::inRange(-1000, 1900));
  f.irregularity_cdb = static_cast<std::int16_t>(f.parameterization == Parameterization::log ? *rc::gen::inRange(0, 800)
                                                                                             : *rc::gen::inRange(-3000, 500));
  f.texel_length_um = static_cast<std::uint16_t>(*rc::gen::inRange(1, 65536));
  f.quantization_ddb = static_cast<std::uint8_t>(*rc::gen::inRange(0, 201));
  f.band_max_device = *rc::gen::arbitrary<bool>();
  f.band_max_cdb = static_cast<std::int16_t>(*rc::gen::inRange(1950, 2500));
  if (*rc::gen::arbitrary<bool>()) f.band_min_cdb = static_cast<std::int16_t>(*rc::gen::inRange(-3000, -1000));
  f.seed = *rc::gen::arbitrary<std::uint64_t>();
  f.out_of_band = *rc::gen::element(OutOfBand::redraw, OutOfBand::clamp);
  f.phase = *rc::gen::element(PhaseMode::continuous, PhaseMode::reset);
  f.fill = *rc::gen::element(Fill::whole_texels, Fill::partial_final_texel);
  if (f.band_max_device) f.band_max_cdb = 1974;  // not stored: keep the default for the comparison
  const auto bytes = write_bitstream(b);
  RC_ASSERT(parse_bitstream(bytes) == b);
}

RC_GTEST_PROP(Bitstream, CoarseLevelsRoundTrip, ()) {
  const auto bits = static_cast<unsigned>(*rc::gen::inRange(1, 17));
  Bitstream b;
  CoarseFields c;
  c.coarse_strength = *rc::gen::arbitrary<std::uint8_t>();
  c.fine_strength = *rc::gen::arbitrary<std::uint8_t>();
  c.bits = static_cast<std::uint8_t>(bits);
  c.predictor = static_cast<std::uint8_t>(*rc::gen::inRange(0, 3));
  c.stride = static_cast<std::uint32_t>(*rc::gen::inRange(1, 100));
  const auto n = static_cast<std::size_t>(*rc::gen::inRange(1, 600));
  const int top = (1 << bits) - 1;
  const bool smooth = *rc::gen::arbitrary<bool>();
  int level = *rc::gen::inRange(0, top + 1);
  for (std::size_t k = 0; k < n; ++k) {
    level = smooth ? std::clamp(level + *rc::gen::inRange(-2, 3), 0, top) : *rc::gen::inRange(0, top + 1);
    c.levels.push_back(static_cast<std::uint16_t>(level));
  }
  b.coarse = c;
  RC_ASSERT(parse_bitstream(write_bitstream(b)) == b);
}

TEST(Bitstream, ToSpecIsExact) {
  Bitstream b;
  b.fine.central_pitch_cdb = 823;
  b.fine.irregularity_cdb = -1234;
  b.fine.texel_length_um = 500;
  b.fine.quantization_ddb = 30;
  b.fine.seed = 99;
  const TexelSpec s = to_spec(b);
  EXPECT_EQ(s.central_pitch.value(), 823 / 100.0);
  EXPECT_EQ(s.irregularity.value(), -1234 / 100.0);
  EXPECT_EQ(s.texel_length.value(), 0.5);
  EXPECT_EQ(s.quantization_db, 3.0);
  EXPECT_EQ(s.seed, 99u);
  EXPECT_EQ(s.band_min.value(), 0.01);
  EXPECT_EQ(s.band_max.value(), to_cpm(Decibels(19.74)).value());
  EXPECT_EQ(s.coarse_strength, 0.0);
  EXPECT_EQ(s.fine_strength, 1.0);
}

TEST(Bitstream, CoarseLevelsDecodeAtTexelCentres) {
  const Bitstream b = coarse_example(6, 1, 3, 40);
  const TexelSpec s = to_spec(b);
  const auto c = sample_at_texel_centres(s.coarse, s.texel_length, 120);
  for (std::size_t j = 0; j < 40; ++j) EXPECT_EQ(c[j * 3], b.coarse->levels[j] / 63.0) << j;
  EXPECT_EQ(s.coarse_strength, 153 / 255.0);
  EXPECT_EQ(s.fine_strength, 128 / 255.0);
}

TEST(Bitstream, FromSpecQuantizesAndFoldsConstantProfiles) {
  TexelSpec s;
  s.central_pitch = Decibels(8.004);
  s.irregularity = Decibels(-3.996);
  s.seed = 5;
  Bitstream b = from_spec(s, Millimetres(100.0));
  EXPECT_EQ(b.fine.central_pitch_cdb, 800);
  EXPECT_EQ(b.fine.irregularity_cdb, -400);
  EXPECT_TRUE(b.fine.band_max_device);  // band_max 0 stays the device's Nyquist
  EXPECT_FALSE(b.coarse.has_value());
  s.coarse_strength = 0.5;
  s.coarse = ConstantProfile{0.4};  // e = 1 − 0.5·0.6 = 0.7 → C' = 0.3 with c = 0
  b = from_spec(s, Millimetres(100.0));
  ASSERT_TRUE(b.coarse.has_value());
  EXPECT_EQ(b.coarse->bits, 0);
  EXPECT_EQ(b.coarse->coarse_strength, 77);  // round(0.3·255)
  s.coarse = SineProfile{Millimetres(5.0), 0.0};
  b = from_spec(s, Millimetres(100.0), 8);
  ASSERT_TRUE(b.coarse.has_value());
  EXPECT_EQ(b.coarse->levels.size(), 400u);
  s.texel_length = Millimetres(70.0);
  EXPECT_THROW((void)from_spec(s, Millimetres(100.0)), InvalidArgument);
}

/// Decoding a bitstream and rendering the equivalent document give identical bytes.
void expect_bit_exact(const Bitstream& b, const std::string& device_name) {
  const DeviceProfile device = load_device(device_name);
  const Document decoded = decode_document(b, device);
  const Document reparsed = parse_document(document_json(decoded), "equivalent document");
  const auto x = prepare_surface(decoded).render_native(device.format);
  const auto y = prepare_surface(reparsed).render_native(device.format);
  ASSERT_EQ(x.size(), device.native_bytes());
  EXPECT_TRUE(x == y) << device_name;
}

TEST(Bitstream, DecodingIsBitExactWithTheEquivalentDocument) {
  Bitstream fine;
  fine.fine.seed = 3;
  for (const char* d : {"tpad", "generic", "tpad-tablet"}) {
    expect_bit_exact(fine, d);
    expect_bit_exact(coarse_example(6, 2, 1, 400), d);
    expect_bit_exact(coarse_example(4, 1, 5, 80), d);
  }
}

TEST(Bitstream, TheTextureIsDeviceIndependent) {
  // The same texel draws on every device: the band top is in the stream.
  Bitstream b;
  b.fine.irregularity_cdb = 300;  // wide, so redraws at the band edges happen
  const Surface tpad = prepare_surface(decode_document(b, load_device("tpad")));
  const Surface generic = prepare_surface(decode_document(b, load_device("generic")));
  const auto& t1 = dynamic_cast<const TexelTexture&>(*tpad.regions()[0].texture).texels();
  const auto& t2 = dynamic_cast<const TexelTexture&>(*generic.regions()[0].texture).texels();
  ASSERT_GT(t1.size(), 390u);
  for (std::size_t k = 0; k < std::min(t1.size(), t2.size()); ++k) {
    EXPECT_EQ(t1[k].frequency.value(), t2[k].frequency.value()) << k;
    EXPECT_EQ(t1[k].phase_cycles, t2[k].phase_cycles) << k;
  }
}

TEST(Bitstream, RejectsTruncatedStreams) {
  for (const Bitstream& b : {Bitstream{}, coarse_example(6, 1, 1, 300)}) {
    const auto bytes = write_bitstream(b);
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      const std::vector<std::byte> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
      EXPECT_THROW((void)parse_bitstream(cut), FormatError) << n;
    }
  }
  EXPECT_NE(message_of(bytes_of({0x54, 0x01, 0x00})).find("truncated"), std::string::npos);
}

TEST(Bitstream, RejectsOversizedStreams) {
  auto bytes = write_bitstream(Bitstream{});
  bytes.insert(bytes.end() - 1, std::byte{0x00});
  bytes.back() = std::byte{crc8(std::span(bytes.data(), bytes.size() - 1))};  // a valid CRC over the extra byte
  EXPECT_NE(message_of(bytes).find("oversized"), std::string::npos) << message_of(bytes);
}

TEST(Bitstream, RejectsWrongMagicAndVersion) {
  auto bytes = write_bitstream(Bitstream{});
  auto v2 = bytes;
  v2[1] = std::byte{2};
  EXPECT_NE(message_of(v2).find("unsupported bitstream version 2"), std::string::npos) << message_of(v2);
  auto bad = bytes;
  bad[0] = std::byte{0x7B};  // '{': a JSON document given by mistake
  EXPECT_NE(message_of(bad).find("not a Texel bitstream"), std::string::npos);
  EXPECT_NE(message_of({}).find("empty"), std::string::npos);
}

TEST(Bitstream, RejectsCorruption) {
  const auto bytes = write_bitstream(Bitstream{});
  for (std::size_t i = 2; i < bytes.size(); ++i)
    for (int bit = 0; bit < 8; ++bit) {
      auto v = bytes;
      v[i] ^= static_cast<std::byte>(1u << bit);
      EXPECT_THROW((void)parse_bitstream(v), FormatError) << i << ":" << bit;  // CRC-8 catches every single-bit error
    }
}

TEST(Bitstream, RejectsUnrenderableTextures) {
  Bitstream b;
  b.fine.central_pitch_cdb = 3000;  // 30 dB = 1000 cpm, above the stored band top
  auto bytes = write_bitstream(b);
  EXPECT_NE(message_of(bytes).find("unrenderable"), std::string::npos) << message_of(bytes);
  b = Bitstream{};
  b.fine.parameterization = Parameterization::log;
  b.fine.irregularity_cdb = -100;  // log parameterization needs I >= 0
  EXPECT_THROW((void)parse_bitstream(write_bitstream(b)), FormatError);
}

TEST(Bitstream, WriterRejectsUnrepresentableFields) {
  Bitstream b;
  b.fine.texel_length_um = 0;
  EXPECT_THROW((void)write_bitstream(b), InvalidArgument);
  b = coarse_example(4, 1, 1, 10);
  b.coarse->levels[3] = 16;  // above 2^4 − 1
  EXPECT_THROW((void)write_bitstream(b), InvalidArgument);
}

}  // namespace
