// Binary MPEG-I Haptics streams (.hmpg, texel/interchange.hpp, docs/
// interchange.md "Binary .hmpg"): write -> read -> write is bit-exact, the
// samples come back within the tolerance plus the amplitude code's half step,
// long effects are split within the 16-bit positions, and malformed streams
// (truncated, bad codes, huge counts, mutated) are refused with one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/specs.hpp"
#include "interchange_support.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/random.hpp"
#include "texel/signal.hpp"
#include "texel/surface.hpp"

using namespace texel;
using nlohmann::json;

namespace {

Document fine_doc(const std::string& device = "tpad") {
  // tpad-tablet's grid ends at 4.25 cpm: a lower Central Pitch there.
  const double pitch = device == "tpad-tablet" ? 0.0 : 10.0;
  return make_document(load_device(device), test_support::fine_spec(pitch, -5, device == "tpad-tablet" ? 1.0 : 0.25, 7));
}

hjif::ExportOptions options() {
  hjif::ExportOptions o;
  o.date = "2026-11-26T14:06:29Z";
  return o;
}

double map_error(const hjif::Experience& e, const Document& doc) { return test_support::max_map_error(e, doc); }

std::string refusal(const std::vector<std::byte>& bytes) {
  try {
    (void)hjif::parse_hjif(hmpg::decode(bytes, "x.hmpg"), "x.hmpg");
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Hmpg, WriteReadWriteIsBitExactAndTheMapComesBackWithinTheStatedTolerance) {
  for (const std::string device : {"tpad", "generic", "tpad-tablet"}) {
    SCOPED_TRACE(device);
    const Document doc = fine_doc(device);
    const hmpg::Exported b = hmpg::export_hmpg(doc, options());
    const std::string text = hmpg::decode(b.bytes);
    EXPECT_EQ(hmpg::encode(text), b.bytes) << "write -> read -> write changed the bytes";
    EXPECT_TRUE(hjif::conformance_errors(text).empty()) << hjif::conformance_errors(text).front();
    const hjif::Experience e = hjif::parse_hjif(text);
    EXPECT_FALSE(e.carried.has_value());  // the document does not fit the 255-byte description
    const double err = map_error(e, doc);
    EXPECT_DOUBLE_EQ(err, b.stats.max_error);
    // The stated tolerance: the export's, plus half the 8-bit amplitude step (Texel rounds to the nearest code),
    // plus the gain's 32-bit code (1 is written as 1.0000006).
    EXPECT_LE(err, hjif::default_tolerance + hmpg::amplitude_step / 2 + 1e-6) << err;
    std::cout << "[ hmpg ] " << device << ": " << b.bytes.size() << " bytes, max error " << err << "\n";
  }
}

TEST(Hmpg, EveryModalityAndRegionLayoutTexelWritesRoundTrips) {
  const Document regions = test_support::two_region_document(load_device("tpad"));
  hjif::ExportOptions v = options();
  v.modality = hjif::Modality::vibrotactile_texture;
  for (const auto& [doc, o] : {std::pair{regions, options()}, std::pair{fine_doc(), v}}) {
    const hmpg::Exported b = hmpg::export_hmpg(doc, o);
    EXPECT_EQ(hmpg::encode(hmpg::decode(b.bytes)), b.bytes);
    const hjif::Experience e = hjif::parse_hjif(hmpg::decode(b.bytes));
    EXPECT_EQ(e.perceptions.size(), doc.regions.size());
    EXPECT_EQ(e.perceptions.front().modality, hjif::modality_name(o.modality));
    EXPECT_LE(map_error(e, doc), hjif::default_tolerance + hmpg::amplitude_step / 2 + 1e-6);
  }
}

TEST(Hmpg, EffectsLongerThanSixteenBitPositionsAreSplitOnTheirLine) {
  // One Linear curve over 300,000 ticks with a 100,000-tick segment.
  json j = json::parse(R"({"version":"2025","profile":"Main","level":1,"date":"2026-11-26T00:00:00Z","description":"d",
    "timescale":1000,"avatars":[],"syncs":[],"perceptions":[{"id":0,"avatar_id":0,"description":"p",
    "perception_modality":"Friction","unit_exponent":-3,"effect_library":[],"reference_devices":[{"id":1,"name":"tpad"}],
    "channels":[{"id":0,"description":"c","gain":1.0,"mixing_coefficient":1.0,"body_part_mask":0,"reference_device_id":1,
    "bands":[{"band_type":"Curve","curve_type":"Linear","lower_frequency_limit":0,"upper_frequency_limit":10,
    "effects":[{"effect_type":"Basis","position":500,"keyframes":[]}]}]}]}]})");
  auto& kfs = j["perceptions"][0]["channels"][0]["bands"][0]["effects"][0]["keyframes"];
  std::vector<std::pair<std::int64_t, double>> points{{0, 0.0}, {100000, 1.0}, {100001, 0.2}};
  for (std::int64_t t = 100100; t <= 300000; t += 100) points.emplace_back(t, 0.5 + 0.4 * std::sin(t * 1e-3));
  for (const auto& [t, a] : points) kfs.push_back({{"relative_position", t}, {"amplitude_modulation", a}});
  const std::string text = j.dump();
  const std::vector<std::byte> bytes = hmpg::encode(text);
  EXPECT_EQ(hmpg::encode(hmpg::decode(bytes)), bytes);
  const json back = json::parse(hmpg::decode(bytes));
  EXPECT_GT(back["perceptions"][0]["channels"][0]["bands"][0]["effects"].size(), 4u);
  const hjif::Experience a = hjif::parse_hjif(text);
  const hjif::Experience b = hjif::parse_hjif(hmpg::decode(bytes));
  std::vector<double> x;
  for (std::int64_t t = 500; t <= 300500; t += 7) x.push_back(static_cast<double>(t) / 1000.0);  // whole ticks, in mm
  const auto ya = hjif::evaluate(a, x);
  const auto yb = hjif::evaluate(b, x);
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) worst = std::max(worst, std::fabs(ya[i] - yb[i]));
  EXPECT_LE(worst, hmpg::amplitude_step / 2 + 1e-6);  // the amplitude code, and the gain's (1.0000006)
}

TEST(Hmpg, MalformedStreamsAreRefusedWithOneLine) {
  const hmpg::Exported b = hmpg::export_hmpg(fine_doc("tpad-tablet"), options());  // 4.9 kB
  const std::vector<std::byte>& good = b.bytes;
  // Under the sanitizers (20x slower here: every stream is decoded to and
  // parsed from JSON) a fifth of the cuts and a tenth of the mutants below;
  // fuzz.hmpg.replay covers the decoder there too.
#if defined(__SANITIZE_ADDRESS__)
  constexpr std::size_t cuts = 60;
  constexpr std::uint64_t mutants = 200;
#else
  constexpr std::size_t cuts = 300;
  constexpr std::uint64_t mutants = 2000;
#endif
  // Truncated anywhere: refused, one line (or, cut between units, read as what it holds).
  for (std::size_t n = 0; n < good.size(); n += std::max<std::size_t>(1, good.size() / cuts)) {
    const std::vector<std::byte> cut(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    try {
      (void)hjif::parse_hjif(hmpg::decode(cut, "x.hmpg"), "x.hmpg");
    } catch (const FormatError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("x.hmpg"), std::string::npos) << e.what();
    }
  }
  EXPECT_NE(refusal(std::vector<std::byte>(good.begin(), good.begin() + 40)).find("declares"), std::string::npos);
  EXPECT_NE(refusal(std::vector<std::byte>(good.begin(), good.begin() + 5)).find("truncated"), std::string::npos);
  // A bad unit type, a bad packet type, a modality code outside the syntax.
  std::vector<std::byte> bad = good;
  bad[0] = std::byte{0xFC};
  EXPECT_NE(refusal(bad).find("unit's type is 63"), std::string::npos) << refusal(bad);
  bad = good;
  bad[9] = std::byte{0xFC};
  EXPECT_NE(refusal(bad).find("packet's type is 63"), std::string::npos) << refusal(bad);
  // A unit declaring 2^32 - 1 bytes.
  bad = good;
  for (int i = 4; i <= 8; ++i) bad[static_cast<std::size_t>(i)] |= static_cast<std::byte>(i == 4 ? 0x0F : i == 8 ? 0xF0 : 0xFF);
  EXPECT_NE(refusal(bad).find("declares"), std::string::npos) << refusal(bad);
  // Mutations: only texel errors escape.
  const CounterRng rng(24, 0);
  std::size_t refused = 0;
  for (std::uint64_t k = 0; k < mutants; ++k) {
    std::vector<std::byte> m = good;
    const int flips = 1 + static_cast<int>(rng.below(k * 4, 4));
    for (int f = 0; f < flips; ++f)
      m[rng.below(k * 4 + 1 + f, m.size())] ^= static_cast<std::byte>(1U << rng.below(k * 4 + 2 + f, 8));
    try {
      const std::string text = hmpg::decode(m, "m.hmpg");
      (void)hjif::parse_hjif(text, "m.hmpg");
    } catch (const Error& e) {
      ++refused;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
  EXPECT_GT(refused, 0u);
}

TEST(Hmpg, TheSignalLoaderReadsHmpgWhereverHjifIsAnInput) {
  const Document doc = fine_doc();
  const hmpg::Exported b = hmpg::export_hmpg(doc, options());
  SignalOptions o;
  const Signal s = decode_signal(b.bytes, SignalFormat::hmpg, o, "a.hmpg");
  EXPECT_EQ(s.format, SignalFormat::hmpg);
  EXPECT_EQ(s.samples.size(), static_cast<std::size_t>(doc.device.samples));
  EXPECT_EQ(signal_format_of("x.hmpg"), SignalFormat::hmpg);
}

namespace {

/// Bits, most significant first: a stream built by hand, field by field.
struct Bits {
  std::vector<bool> v;
  Bits& put(std::uint64_t x, int n) {
    for (int i = n - 1; i >= 0; --i) v.push_back(((x >> i) & 1U) != 0);
    return *this;
  }
  Bits& text(const std::string& s, std::size_t declared) {
    put(declared, 8);
    for (char c : s) put(static_cast<unsigned char>(c), 8);
    return *this;
  }
  Bits& pad() {
    while (v.size() % 8) v.push_back(false);
    return *this;
  }
  Bits& packet(int type, Bits payload) {
    payload.pad();
    put(static_cast<std::uint64_t>(type), 6).put(payload.v.size() / 8, 17).put(0, 1);
    v.insert(v.end(), payload.v.begin(), payload.v.end());
    return *this;
  }
  Bits& unit(int type, std::uint32_t duration, const Bits& packets) {
    put(static_cast<std::uint64_t>(type), 6).put(0, 2).put(0, 4).put(duration, 24).put(packets.v.size() / 8, 32).put(0, 4);
    v.insert(v.end(), packets.v.begin(), packets.v.end());
    return *this;
  }
  std::vector<std::byte> bytes() const {
    std::vector<std::byte> out((v.size() + 7) / 8);
    for (std::size_t i = 0; i < v.size(); ++i)
      if (v[i]) out[i / 8] |= static_cast<std::byte>(0x80U >> (i % 8));
    return out;
  }
};

}  // namespace

// The reference writer stores string lengths in 8 bits modulo 256 and keyframe
// positions in 16 bits modulo 65,536 (docs/interchange.md): both are read back.
TEST(Hmpg, TheReferenceWritersWrappedLengthsAndPositionsAreRead) {
  const std::string description(300, 'd');
  Bits init;
  init.packet(11, Bits().put(0, 32).put(1000, 32).put(128, 24).put(0, 24).put(0, 1));
  init.packet(1, Bits()
                     .text("2023", 4)
                     .text("Main", 4)
                     .put(1, 8)
                     .text("2026-11-26 14:06:29", 19)
                     .text(description, 300 % 256)
                     .put(1, 8)
                     .put(0, 8));
  init.packet(2, Bits()
                     .put(0, 8)
                     .put(0, 8)
                     .text("p", 1)
                     .put(12, 8)
                     .put(0, 8)
                     .put(0, 16)
                     .put(0, 1)
                     .put(0xFD, 8)
                     .put(0, 8)
                     .put(1, 8)
                     .put(1, 8)
                     .text("tpad", 4)
                     .put(0, 32)
                     .put(0, 12)
                     .put(1, 16));
  init.packet(3, Bits()
                     .put(0, 16)
                     .put(0, 8)
                     .put(0, 8)
                     .text("c", 1)
                     .put(1, 8)
                     .put(2147698432ULL, 32)
                     .put(429497, 32)
                     .put(1, 8)
                     .put(0, 32)
                     .put(0, 32)
                     .put(0, 16)
                     .put(1, 8));
  init.packet(4, Bits().put(0, 8).put(0, 8).put(0, 16).put(0, 8).put(1, 3).put(2, 4).put(0, 16).put(10, 16).put(1, 16));
  Bits data;
  // One Curve effect at 0: keyframes at 0, 40000 and 80000 ticks (written 14464), amplitudes codes 128, 255, 128.
  data.packet(5, Bits()
                     .put(0, 1)
                     .put(0, 8)
                     .put(0, 16)
                     .put(0, 8)
                     .put(1, 16)
                     .put(0, 2)
                     .put(0, 25)
                     .put(3, 16)
                     .put(128, 8)
                     .put(0, 16)
                     .put(255, 8)
                     .put(40000, 16)
                     .put(128, 8)
                     .put(80000 % 65536, 16));
  Bits stream;
  stream.unit(0, 0, init).unit(1, 128, data);
  const std::string text = hmpg::decode(stream.bytes(), "rm.hmpg");
  const json j = json::parse(text);
  EXPECT_EQ(j["description"], description);
  EXPECT_EQ(j["perceptions"][0]["channels"][0]["bands"][0]["effects"][0]["keyframes"][2]["relative_position"], 80000);
  const hjif::Experience e = hjif::parse_hjif(text, "rm.hmpg");
  const double x[] = {40.0, 60.0};  // mm at 1000 ticks per mm
  const auto y = hjif::evaluate(e, x);
  const double gain = 2147698431.0 / 4294967295.0 * 20000.0 - 10000.0;
  EXPECT_NEAR(y[0], gain, 1e-5);
  EXPECT_NEAR(y[1], gain * (1.0 + 1.0 / 255) / 2, 1e-5);
}
