// Exact transcoding (issue #11, item 1): a document that holds Texel
// parameters goes to a bitstream without estimation, and decoding that
// bitstream on any device renders the bytes the document renders there;
// values the bitstream cannot hold are reported, never silently changed.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "../support/specs.hpp"
#include "../support/temp_dir.hpp"
#include "texel/codec.hpp"
#include "texel/error.hpp"
#include "texel/surface.hpp"

namespace {

using namespace texel;
using namespace texel::codec;
using texel::test_support::TempDir;

// The document's map on `device` (as `texel render DOC --device X`).
std::vector<std::byte> rendered(Document doc, const DeviceProfile& device) {
  doc.device = device;
  return prepare_surface(doc).render_native(device.format);
}

std::vector<std::byte> decoded(const std::vector<std::byte>& bytes, const DeviceProfile& device) {
  return prepare_surface(decode_document(parse_bitstream(bytes), device)).render_native(device.format);
}

TexelSpec fine(double pitch_db, double irregularity_db, double length_mm, std::uint64_t seed) {
  return test_support::fine_spec(pitch_db, irregularity_db, length_mm, seed);
}

TEST(Transcode, FineOnlyDocumentsDecodeToTheirOwnBytesOnEveryDevice) {
  std::vector<TexelSpec> specs;
  specs.push_back(fine(4, 0, 0.5, 3));
  specs.push_back(fine(-3.25, -12.5, 0.25, 1234567));
  TexelSpec q = fine(2, -2, 0.75, 9);
  q.quantization_db = 1.5;
  specs.push_back(q);
  TexelSpec r = fine(5, -5, 0.3, 11);
  r.phase = PhaseMode::reset;
  r.fill = Fill::partial_final_texel;
  specs.push_back(r);
  TexelSpec lg = fine(1, 3, 1.0, 5);
  lg.parameterization = Parameterization::log;
  specs.push_back(lg);
  TexelSpec wide = fine(0, 4, 0.25, 77);
  wide.out_of_band = OutOfBand::clamp;
  specs.push_back(wide);

  const DeviceProfile tpad = load_device("tpad");
  for (const TexelSpec& s : specs) {
    const Document doc = make_document(tpad, s);
    ASSERT_FALSE(not_transcodable(doc).has_value());
    const Transcoded t = transcode(doc);
    EXPECT_TRUE(t.exact);
    EXPECT_TRUE(t.losses.empty()) << t.losses.front();
    EXPECT_FALSE(t.bitstream.coarse.has_value());
    EXPECT_EQ(t.spec.seed, s.seed);
    for (const char* name : {"tpad", "tpad-tablet", "generic"}) {
      const DeviceProfile d = load_device(name);
      EXPECT_EQ(decoded(t.bytes, d), rendered(doc, d)) << name << " P " << s.central_pitch.value();
    }
    // Idempotent: the bitstream transcodes to itself, and the decoded
    // document to the same bytes.
    EXPECT_EQ(transcode(parse_bitstream(t.bytes)).bytes, t.bytes);
    EXPECT_EQ(transcode(decode_document(parse_bitstream(t.bytes), tpad)).bytes, t.bytes);
  }
}

TEST(Transcode, CoarseProfilesThatTheLevelsHoldAreExact) {
  // Envelope levels and strengths on the bitstream's own steps (n/255,
  // k/(2^b − 1)): stored exactly, with the fewest bits that hold them.
  const DeviceProfile tpad = load_device("tpad");
  TexelSpec s = fine(6, -6, 0.5, 21);
  s.coarse_strength = 0.2;  // 51/255
  s.fine_strength = 0.6;    // 153/255
  std::vector<double> v;
  for (int k = 0; k < 203; ++k) v.push_back((k % 4) / 3.0);
  s.coarse = ValuesProfile{v};
  const Document doc = make_document(tpad, s);
  const Transcoded t = transcode(doc);
  ASSERT_TRUE(t.bitstream.coarse.has_value());
  EXPECT_EQ(t.bitstream.coarse->bits, 2);
  EXPECT_TRUE(t.exact) << (t.losses.empty() ? "" : t.losses.front());
  EXPECT_EQ(decoded(t.bytes, tpad), rendered(doc, tpad));
  EXPECT_EQ(transcode(parse_bitstream(t.bytes)).bytes, t.bytes);
}

TEST(Transcode, WhatTheBitstreamCannotHoldIsReported) {
  const DeviceProfile tpad = load_device("tpad");
  // A pitch between 0.01 dB steps.
  const Transcoded p = transcode(make_document(tpad, fine(8.004, 0, 0.5, 3)));
  EXPECT_FALSE(p.exact);
  ASSERT_EQ(p.losses.size(), 1u);
  EXPECT_NE(p.losses[0].find("central_pitch_db 8.004 is stored as 8"), std::string::npos) << p.losses[0];

  // A sinusoidal coarse profile at C 0.5 (not n/255): stored with 8-bit
  // levels, and the envelope error is stated.
  TexelSpec s = fine(10, -5, 0.25, 1);
  s.coarse_strength = 0.5;
  s.coarse = SineProfile{Millimetres(5.0), 0.0};
  const Document doc = make_document(tpad, s);
  const Transcoded c = transcode(doc);
  EXPECT_FALSE(c.exact);
  EXPECT_EQ(c.bitstream.coarse->bits, 8);
  ASSERT_FALSE(c.losses.empty());
  EXPECT_NE(c.losses.back().find("coarse envelope"), std::string::npos) << c.losses.back();
  // The caller may ask for finer levels.
  TranscodeOptions o;
  o.coarse_bits = 16;
  EXPECT_EQ(transcode(doc, o).bitstream.coarse->bits, 16);
  o.coarse_bits = 17;
  EXPECT_THROW((void)transcode(doc, o), InvalidArgument);
  TranscodeOptions small;
  small.max_bytes = 20;
  try {
    (void)transcode(doc, small);
    ADD_FAILURE() << "a 20-byte budget held a coarse profile";
  } catch (const FieldError& e) {
    EXPECT_EQ(e.field(), "max_bytes");
  }
}

TEST(Transcode, OnlyOneTexelTextureOverTheWholeDeviceIsTranscoded) {
  const DeviceProfile tpad = load_device("tpad");
  Document two = make_document(tpad, fine(4, 0, 0.5, 3));
  two.regions.front().length = Millimetres(50.0);
  RegionSpec right;
  right.start = Millimetres(50.0);
  two.regions.push_back(right);
  EXPECT_NE(not_transcodable(two)->find("2 regions"), std::string::npos);
  EXPECT_THROW((void)transcode(two), InvalidArgument);

  Document part = make_document(tpad, fine(4, 0, 0.5, 3));
  part.regions.front().length = Millimetres(50.0);
  EXPECT_NE(not_transcodable(part)->find("50 mm long"), std::string::npos);

  ReferenceSpec ref;
  ref.name = "4sin";
  EXPECT_NE(not_transcodable(make_reference_document(tpad, ref))->find("reference '4sin'"), std::string::npos);
}

TEST(Transcode, FilesThatHoldParametersAreTranscodedAndSampleFilesAreNot) {
  TempDir dir("transcode");
  const DeviceProfile tpad = load_device("tpad");
  const Document doc = make_document(tpad, fine(4, 0, 0.5, 3));
  const std::string path = dir.at("d.texel.json");
  save_document(doc, path);
  const Transcoded want = transcode(doc);

  std::string why;
  const auto t = transcode_file(path, {}, {}, &why);
  ASSERT_TRUE(t.has_value()) << why;
  EXPECT_EQ(t->bytes, want.bytes);

  const std::string stream = dir.at("d.texel");
  std::ofstream(stream, std::ios::binary)
      .write(reinterpret_cast<const char*>(want.bytes.data()), static_cast<std::streamsize>(want.bytes.size()));
  const auto again = transcode_file(stream);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->bytes, want.bytes);

  // Re-targeted to another device: the document as rendered there.
  SignalOptions generic;
  generic.device = load_device("generic");
  const auto g = transcode_file(path, generic);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(decoded(g->bytes, *generic.device), rendered(doc, *generic.device));

  // A region of it, a sample file, a reference document: not transcoded.
  SignalOptions region;
  region.region = SignalOptions::Region{"", Millimetres(10.0), Millimetres(20.0)};
  EXPECT_FALSE(transcode_file(path, region, {}, &why).has_value());
  EXPECT_NE(why.find("region"), std::string::npos);
  const std::string npy = dir.at("m.npy");
  std::ofstream(npy) << "not read";
  EXPECT_FALSE(transcode_file(npy, {}, {}, &why).has_value());
  EXPECT_NE(why.find("samples"), std::string::npos);
  ReferenceSpec ref;
  ref.name = "pink";
  const std::string refdoc = dir.at("pink.texel.json");
  save_document(make_reference_document(tpad, ref), refdoc);
  EXPECT_FALSE(transcode_file(refdoc, {}, {}, &why).has_value());
  EXPECT_NE(why.find("reference"), std::string::npos);
}

}  // namespace
