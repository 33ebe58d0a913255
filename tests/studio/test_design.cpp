// The designer's library API (design.hpp): the map is the renderer's, bit
// for bit; the histogram counts the texture's own draw and its expected
// counts come from the same distribution; the spectrum peaks at the central
// pitch; the encoded size follows the parameters; match, import and export
// round-trip through the codec and the file formats.
#include <gtest/gtest.h>

#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "texel/bitstream.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/studio/design.hpp"

using namespace texel;
using namespace texel::studio;

namespace {

Document tpad_texel(double pitch_db, double irregularity_db, std::uint64_t seed = 1) {
  TexelSpec spec;
  spec.central_pitch = Decibels(pitch_db);
  spec.irregularity = Decibels(irregularity_db);
  spec.seed = seed;
  return make_document(load_device("tpad"), spec);
}

// The studies' layout: a reference on the left, a Texel texture on the right.
Document two_regions() {
  return parse_document(R"({"format":"texel-document","version":2,"device":"tpad","regions":[
    {"name":"left","start_mm":0,"length_mm":50.88,"texture":{"kind":"reference","name":"4sin","seed":1}},
    {"name":"right","start_mm":50.88,"texture":{"kind":"texel","central_pitch_db":8,"irregularity_db":-3,"texel_length_mm":0.25,"seed":1}}]})");
}

}  // namespace

TEST(DesignView, MapIsTheRenderersBitForBit) {
  for (const Document& doc : {tpad_texel(10, -5), two_regions()}) {
    const DesignView v = design_view(doc);
    const std::vector<double> map = prepare_surface(doc).render();
    ASSERT_EQ(v.map.size(), map.size());
    ASSERT_EQ(v.grid.count, static_cast<std::int64_t>(map.size()));
    for (std::size_t i = 0; i < map.size(); ++i) ASSERT_EQ(v.map[i], static_cast<float>(map[i])) << i;
  }
}

TEST(DesignView, HistogramCountsTheDrawnTexels) {
  const Document doc = tpad_texel(10, -5);
  const DesignView v = design_view(doc);
  const Surface surface = prepare_surface(doc);
  const auto& t = dynamic_cast<const TexelTexture&>(*surface.regions()[0].texture);
  EXPECT_EQ(v.texels, t.texels().size());
  EXPECT_EQ(std::accumulate(v.histogram.counts.begin(), v.histogram.counts.end(), 0.0), static_cast<double>(v.texels));
  ASSERT_EQ(v.histogram.edges_cpm.size(), v.histogram.counts.size() + 1);
  ASSERT_EQ(v.histogram.expected.size(), v.histogram.counts.size());
  // The bins span the draws; the expected counts over them hold nearly all
  // texels (the tails outside the drawn range are small).
  const double expected = std::accumulate(v.histogram.expected.begin(), v.histogram.expected.end(), 0.0);
  EXPECT_GT(expected, 0.95 * static_cast<double>(v.texels));
  EXPECT_LE(expected, static_cast<double>(v.texels) * (1 + 1e-9));
  EXPECT_NEAR(v.central_pitch.value(), 10.0, 1e-9);
  EXPECT_NEAR(v.irregularity.value(), std::pow(10.0, -0.5), 1e-9);
}

TEST(DesignView, EncodedSizeAndNumbersFollowTheParameters) {
  const DesignView a = design_view(tpad_texel(10, -5));
  ASSERT_FALSE(a.encoded.empty());
  EXPECT_EQ(codec::to_spec(codec::parse_bitstream(a.encoded)).central_pitch.value(), 10.0);
  TexelSpec coarse;
  coarse.coarse_strength = 0.8;
  coarse.coarse = SineProfile{Millimetres(10.0), 0.0};
  const DesignView b = design_view(make_document(load_device("tpad"), coarse));
  EXPECT_GT(b.encoded.size(), a.encoded.size());
  const DesignView c = design_view(tpad_texel(12, -5));
  EXPECT_NE(c.map, a.map);
  EXPECT_NE(c.histogram.edges_cpm, a.histogram.edges_cpm);
}

TEST(DesignView, SpectrumPeaksAtTheCentralPitchOfARegularTexture) {
  const DesignView v = design_view(tpad_texel(10, -20));  // 10 cpm, nearly regular
  ASSERT_FALSE(v.spectrum.frequency_cpm.empty());
  EXPECT_LE(v.spectrum.frequency_cpm.size(), 2048u);
  EXPECT_TRUE(std::is_sorted(v.spectrum.frequency_cpm.begin(), v.spectrum.frequency_cpm.end()));
  const auto peak = std::max_element(v.spectrum.magnitude_db.begin(), v.spectrum.magnitude_db.end());
  const double f = v.spectrum.frequency_cpm[static_cast<std::size_t>(peak - v.spectrum.magnitude_db.begin())];
  EXPECT_NEAR(f, 10.0, 0.5);
}

TEST(DesignView, AnalysesTheChosenRegion) {
  const Document doc = two_regions();
  const DesignView right = design_view(doc);  // default: the last Texel region
  EXPECT_EQ(right.analysed, 1u);
  ASSERT_EQ(right.regions.size(), 2u);
  EXPECT_EQ(right.regions[0].kind, "reference");
  EXPECT_EQ(right.regions[1].kind, "texel");
  EXPECT_GT(right.texels, 0u);
  DesignOptions o;
  o.region = 0;
  const DesignView left = design_view(doc, o);
  EXPECT_EQ(left.texels, 0u);
  EXPECT_TRUE(left.encoded.empty());
  EXPECT_FALSE(left.spectrum.frequency_cpm.empty());
  o.region = 2;
  EXPECT_THROW((void)design_view(doc, o), InvalidArgument);
}

// design_view's latency on the tpad is measured by bench/bench_design.cpp
// (texel_bench_design, `make bench`), not timed here.

TEST(Match, EncodesTheReferenceIntoTheOtherRegion) {
  MatchOptions o;
  o.region = 0;
  const MatchView m = match_region(two_regions(), o);
  EXPECT_EQ(m.into, 1u);
  EXPECT_FALSE(m.document.regions[1].reference);
  EXPECT_TRUE(m.document.regions[0].reference);
  EXPECT_EQ(m.document.regions[1].texel.central_pitch, m.result.spec.central_pitch);
  EXPECT_FALSE(m.target.frequency_cpm.empty());
  EXPECT_FALSE(m.match.frequency_cpm.empty());
  EXPECT_GT(m.result.bytes.size(), 0u);
}

TEST(ImportExport, DocumentAndBitstreamRoundTrip) {
  const Document doc = two_regions();
  const ExportFile json = export_file(doc, ExportFormat::document);
  EXPECT_EQ(json.name, "texture.texel.json");
  const ImportResult back = import_file(json.name, byte_view(json.data), {});
  EXPECT_EQ(back.kind, ImportKind::document);
  EXPECT_EQ(document_json(back.document), document_json(doc));

  // A .texel holds one texture: a two-region document is refused rather than
  // written as its last region; naming the region writes that one.
  try {
    (void)export_file(doc, ExportFormat::bitstream);
    ADD_FAILURE() << "a two-region document exported as one .texel";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find(".texel.json to keep every region"), std::string::npos) << e.what();
  }
  const ExportFile bits = export_file(doc, ExportFormat::bitstream, 1);
  const ImportResult decoded = import_file("x.texel", byte_view(bits.data), {});
  EXPECT_EQ(decoded.kind, ImportKind::bitstream);
  EXPECT_EQ(decoded.document.regions.size(), 1u);
  EXPECT_NEAR(decoded.document.regions[0].texel.central_pitch.value(), 8.0, 1e-9);
  EXPECT_THROW((void)export_file(doc, ExportFormat::bitstream, 0), InvalidArgument);
}

// The studio writes .hjif as `texel export -o x.hjif` does: the library's export, byte for byte (issue #37).
TEST(ImportExport, HjifIsTheLibrarysExport) {
  ::setenv("SOURCE_DATE_EPOCH", "1764165989", 1);  // both files dated alike
  const Document doc = two_regions();
  const ExportFile f = export_file(doc, ExportFormat::hjif);
  ::unsetenv("SOURCE_DATE_EPOCH");
  EXPECT_EQ(f.name, "texture.hjif");
  EXPECT_EQ(f.mime, "application/json");
  ::setenv("SOURCE_DATE_EPOCH", "1764165989", 1);
  const std::string want = hjif::export_hjif(doc).json;
  ::unsetenv("SOURCE_DATE_EPOCH");
  EXPECT_EQ(f.data, want);
  EXPECT_TRUE(hjif::conformance_errors(f.data).empty());
  EXPECT_EQ(parse_export_format("hjif"), ExportFormat::hjif);
}

TEST(ImportExport, DeviceFilesAndSignalsGoThroughTheCodec) {
  const Document doc = tpad_texel(10, -5);
  const std::vector<double> map = prepare_surface(doc).render();
  const ExportFile bin = export_file(doc, ExportFormat::device);
  EXPECT_EQ(bin.data.size(), map.size() * 2);  // tpad: u16le
  const ExportFile npy = export_file(doc, ExportFormat::npy);
  EXPECT_EQ(parse_npy(npy.data, "npy"), map);
  const ExportFile csv = export_file(doc, ExportFormat::csv);
  EXPECT_EQ(parse_csv_columns(csv.data, "csv").second.size(), map.size());
  for (const ExportFile* f : {&bin, &npy}) {
    const ImportResult r = import_file(f->name, byte_view(f->data), {});
    EXPECT_EQ(r.kind, ImportKind::signal);
    ASSERT_TRUE(r.encoded);
    EXPECT_NEAR(r.encoded->spec.central_pitch.value(), 10.0, 0.5) << f->name;
  }
  const std::string junk = "not a number\n";
  EXPECT_THROW((void)import_file("a.csv", byte_view(junk), {}), Error);
  EXPECT_THROW((void)import_file("a.exe", {}, {}), InvalidArgument);
  EXPECT_THROW((void)parse_export_format("png"), InvalidArgument);
}
