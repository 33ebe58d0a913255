// Texture documents (document.hpp, docs/format.md): parse(document_json(d))
// == d for any valid document; unknown keys, wrong types, bad values and
// unsupported versions are rejected with the field's JSON path; saving is
// atomic; a document renders like the texture it describes.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>

#include <unistd.h>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

using namespace texel;
namespace fs = std::filesystem;

namespace {

// Field-by-field equality: a missed field in the serializer or parser shows
// up as a difference here (document_json text equality alone would not catch
// a field that neither side handles).
bool same_coarse(const CoarseProfile& a, const CoarseProfile& b) {
  if (a.index() != b.index()) return false;
  if (const auto* x = std::get_if<ConstantProfile>(&a)) return x->value == std::get<ConstantProfile>(b).value;
  if (const auto* x = std::get_if<SineProfile>(&a)) {
    const auto& y = std::get<SineProfile>(b);
    return x->period == y.period && x->phase_deg == y.phase_deg;
  }
  if (const auto* x = std::get_if<ValuesProfile>(&a)) return x->values == std::get<ValuesProfile>(b).values;
  if (const auto* x = std::get_if<PointsProfile>(&a)) return x->points == std::get<PointsProfile>(b).points;
  const auto& x = std::get<SampledProfile>(a);
  const auto& y = std::get<SampledProfile>(b);
  return x.spacing.value() == y.spacing.value() && x.values == y.values;
}

void expect_same(const TexelSpec& a, const TexelSpec& b) {
  EXPECT_EQ(a.central_pitch, b.central_pitch);
  EXPECT_EQ(a.irregularity, b.irregularity);
  EXPECT_EQ(a.texel_length, b.texel_length);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.parameterization, b.parameterization);
  EXPECT_EQ(a.out_of_band, b.out_of_band);
  EXPECT_EQ(a.band_min, b.band_min);
  EXPECT_EQ(a.band_max, b.band_max);
  EXPECT_EQ(a.quantization_db, b.quantization_db);
  EXPECT_EQ(a.phase, b.phase);
  EXPECT_EQ(a.fill, b.fill);
  EXPECT_EQ(a.coarse_strength, b.coarse_strength);
  EXPECT_EQ(a.fine_strength, b.fine_strength);
  EXPECT_TRUE(same_coarse(a.coarse, b.coarse)) << kind_name(a.coarse) << " vs " << kind_name(b.coarse);
}

void expect_same(const Document& a, const Document& b) {
  // Documents are written with the lowest version that holds them (1 for
  // Texel-only documents), so that is what a round trip gives back.
  EXPECT_EQ(b.version, required_version(a));
  EXPECT_EQ(a.description, b.description);
  EXPECT_EQ(device_profile_json(a.device), device_profile_json(b.device));
  ASSERT_EQ(a.regions.size(), b.regions.size());
  for (std::size_t i = 0; i < a.regions.size(); ++i) {
    EXPECT_EQ(a.regions[i].name, b.regions[i].name);
    EXPECT_EQ(a.regions[i].start, b.regions[i].start);
    EXPECT_EQ(a.regions[i].length, b.regions[i].length);
    EXPECT_EQ(a.regions[i].reference.has_value(), b.regions[i].reference.has_value());
    EXPECT_EQ(a.regions[i].coarse_reference.has_value(), b.regions[i].coarse_reference.has_value());
    expect_same(a.regions[i].texel, b.regions[i].texel);
  }
}

double unit_double() { return static_cast<double>(*rc::gen::arbitrary<std::uint64_t>() >> 11) * 0x1.0p-53; }

TexelSpec random_spec(double region_length_mm) {
  TexelSpec s;
  s.parameterization = *rc::gen::element(Parameterization::moments, Parameterization::log);
  s.central_pitch = Decibels(-10.0 + 29.0 * unit_double());
  s.irregularity = Decibels(s.parameterization == Parameterization::log ? 3.0 * unit_double() : -20.0 + 25.0 * unit_double());
  s.texel_length = Millimetres(0.05 + unit_double());
  s.seed = *rc::gen::arbitrary<std::uint64_t>();
  s.out_of_band = *rc::gen::element(OutOfBand::redraw, OutOfBand::clamp);
  s.band_max = CyclesPerMm(*rc::gen::element(0.0, 94.0));
  s.quantization_db = *rc::gen::element(0.0, 1.0, 3.0, 5.0, 0.5);
  s.phase = *rc::gen::element(PhaseMode::continuous, PhaseMode::reset);
  s.fill = *rc::gen::element(Fill::whole_texels, Fill::partial_final_texel);
  s.coarse_strength = unit_double();
  s.fine_strength = unit_double();
  switch (*rc::gen::inRange(0, 4)) {
    case 0: s.coarse = ConstantProfile{unit_double()}; break;
    case 1: s.coarse = SineProfile{Millimetres(0.5 + 20.0 * unit_double()), -360.0 + 720.0 * unit_double()}; break;
    case 2: {
      ValuesProfile v;
      const std::size_t n = texel_count(Millimetres(region_length_mm), s.texel_length, Fill::partial_final_texel) + 2;
      for (std::size_t k = 0; k < n; ++k) v.values.push_back(unit_double());
      s.coarse = v;
      break;
    }
    default: {
      PointsProfile p;
      double x = -1.0;
      for (int k = 0; k < 5; ++k) {
        x += 0.001 + 30.0 * unit_double();
        p.points.emplace_back(x, unit_double());
      }
      s.coarse = p;
    }
  }
  return s;
}

std::string load_error(const std::string& text) {
  return test_support::message_of<FormatError>([&] { parse_document(text, "doc.texel.json"); });
}

const char* const valid = R"({
  "format": "texel-document",
  "version": 1,
  "device": "tpad",
  "regions": [
    {"name": "left", "start_mm": 0, "length_mm": 50.88,
     "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 1}},
    {"name": "right", "start_mm": 50.88, "length_mm": 50.88,
     "texture": {"kind": "texel", "central_pitch_db": 12, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 2,
                 "coarse": {"kind": "sine", "period_mm": 5}, "coarse_strength": 0.5}}
  ]
})";

/// `valid` with the first occurrence of `from` replaced by `to`.
std::string edit(const std::string& from, const std::string& to) {
  std::string s = valid;
  const auto at = s.find(from);
  if (at == std::string::npos) throw std::logic_error("test bug: '" + from + "' not in the document");
  return s.replace(at, from.size(), to);
}

}  // namespace

RC_GTEST_PROP(Document, RoundTripsThroughJson, ()) {
  Document d;
  d.description = *rc::gen::element(std::string(), std::string("a \"quoted\" description\nwith ünïcode"));
  const int layout = *rc::gen::inRange(0, 3);
  if (layout == 2) {
    DeviceProfile dev;  // an inline, user-defined device
    dev.name = "rig";
    dev.samples = 5000;
    dev.spacing = Millimetres(0.004);
    dev.format = SampleFormat::f32le;
    dev.refresh = Hertz(1000.0);
    d.device = dev;
    d.device_inline = true;
  } else {
    d.device = load_device("tpad");
  }
  const double total = d.device.length().value();
  if (layout == 1) {
    for (int r = 0; r < 2; ++r) {
      RegionSpec spec;
      spec.name = r == 0 ? "left" : "right";
      spec.start = Millimetres(r * 50.88);
      spec.length = Millimetres(50.88);
      spec.texel = random_spec(50.88);
      d.regions.push_back(spec);
    }
  } else {
    RegionSpec spec;
    spec.texel = random_spec(total);
    d.regions.push_back(spec);
  }
  const std::string text = document_json(d);
  const Document back = parse_document(text, "round trip");
  expect_same(d, back);
  RC_ASSERT(!::testing::Test::HasFailure());
  RC_ASSERT(document_json(back) == text);
}

TEST(Document, ValidDocumentParses) {
  const Document d = parse_document(valid, "doc");
  ASSERT_EQ(d.regions.size(), 2u);
  EXPECT_EQ(d.device.name, "tpad");
  EXPECT_EQ(d.regions[1].texel.seed, 2u);
  EXPECT_EQ(d.regions[1].texel.coarse_strength, 0.5);
  EXPECT_EQ(kind_name(d.regions[1].texel.coarse), "sine");
  EXPECT_EQ(d.regions[0].texel.fine_strength, 1.0);  // default
}

TEST(Document, UnknownKeysAreRejectedAtEveryLevel) {
  struct Case {
    std::string from, to, expect;
  };
  const Case cases[] = {
      {"\"version\": 1,", "\"version\": 1, \"colour\": 1,", "the document has unknown key 'colour'"},
      {"\"name\": \"left\",", "\"name\": \"left\", \"strat_mm\": 0,", "regions[0] has unknown key 'strat_mm'"},
      {"\"seed\": 2,", "\"seed\": 2, \"central_pitch\": 3,", "regions[1].texture has unknown key 'central_pitch'"},
      {"\"period_mm\": 5", "\"period_mm\": 5, \"period\": 5", "regions[1].texture.coarse has unknown key 'period'"},
  };
  for (const auto& c : cases) {
    const std::string msg = load_error(edit(c.from, c.to));
    EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind("doc.texel.json: ", 0), 0u) << "errors start with the origin: " << msg;
  }
}

TEST(Document, ErrorsNameTheJsonPath) {
  struct Case {
    std::string from, to, expect;
  };
  const Case cases[] = {
      // wrong types
      {"\"seed\": 2", "\"seed\": \"two\"", "regions[1].texture.seed must be a whole number"},
      {"\"seed\": 1", "\"seed\": -1", "regions[0].texture.seed must be a whole number"},
      {"\"central_pitch_db\": 12", "\"central_pitch_db\": \"12\"",
       "regions[1].texture.central_pitch_db must be a number, got the string"},
      // bad values
      {"\"texel_length_mm\": 0.25, \"seed\": 2", "\"texel_length_mm\": -1, \"seed\": 2",
       "regions[1].texture.texel_length_mm is -1"},
      {"\"coarse_strength\": 0.5", "\"coarse_strength\": 1.5", "regions[1].texture.coarse_strength is 1.5; allowed: 0 … 1"},
      {"\"period_mm\": 5", "\"period_mm\": 0", "regions[1].texture.coarse.period_mm is 0"},
      {"\"kind\": \"sine\"", "\"kind\": \"wavy\"", "regions[1].texture.coarse.kind is 'wavy'"},
      {"\"kind\": \"texel\", \"central_pitch_db\": 10", "\"kind\": \"noise\", \"central_pitch_db\": 10",
       "regions[0].texture.kind is 'noise'"},
      {"\"seed\": 2,", "\"seed\": 2, \"phase\": \"sideways\",", "regions[1].texture.phase is 'sideways'"},
      {"\"central_pitch_db\": 12", "\"central_pitch_db\": 25", "outside the renderable band"},
      {"\"device\": \"tpad\"", "\"device\": \"nosuch\"", "unknown device 'nosuch'"},
      {"\"device\": \"tpad\"", "\"device\": 5", "device must be a device name or an inline profile"},
      {"\"device\": \"tpad\",", "\"device\": \"tpad\", \"device_grid\": {\"spacing_mm\": -1},", "device_grid.spacing_mm is -1"},
      // versions and format tag
      {"\"version\": 1", "\"version\": " + std::to_string(Document::current_version + 1),
       "version is " + std::to_string(Document::current_version + 1) + "; this build of Texel reads versions up to"},
      {"\"version\": 1", "\"version\": 0", "version is 0"},
      {"\"version\": 1", "\"version\": \"1\"", "version must be a whole number"},
      {"\"format\": \"texel-document\"", "\"format\": \"texel-doc\"", "format is 'texel-doc'"},
      // layout
      {"\"start_mm\": 50.88", "\"start_mm\": 40", "overlap"},
      {"\"start_mm\": 50.88", "\"start_mm\": 60", "past the device"},
  };
  for (const auto& c : cases) {
    const std::string msg = load_error(edit(c.from, c.to));
    EXPECT_NE(msg.find(c.expect), std::string::npos) << "edit '" << c.to << "': " << msg;
  }
  EXPECT_NE(load_error(R"({"format": "texel-document", "version": 1, "device": "tpad"})").find("exactly one of"),
            std::string::npos);
  EXPECT_NE(load_error(R"({"format": "texel-document", "device": "tpad", "texture": {}})").find("version is missing"),
            std::string::npos);
}

// Findings of fuzz_document (tests/fuzz/corpus/fuzz_document/crash-*): a few
// hundred bytes of document whose own lengths, not the device's, made
// preparing it allocate 10^11 entries. Each is now a FormatError naming the
// field, raised before anything that size is allocated.
TEST(Document, CostlyLengthsAreRejectedBeforeAllocating) {
  // A region far longer than the device, with a texel length the device's own
  // length would allow (used to prepare 10^11 texels before Surface noticed).
  EXPECT_NE(load_error(R"({"format": "texel-document", "version": 1, "device": "tpad", "regions": [
      {"start_mm": 0, "length_mm": 1e9, "texture": {"kind": "texel", "central_pitch_db": 0, "irregularity_db": -5,
       "texel_length_mm": 0.01, "seed": 1}}]})")
                .find("length_mm 1e+09 mm ends past the device's active length"),
            std::string::npos);
  // 0.001 mm patches over a kilometre-spaced device: 10^11 drawn gaps.
  const std::string km_device = R"("device": {"name": "km", "samples": 100, "spacing_mm": 1e6, "format": "u16le",
      "refresh_hz": 1000, "band_min_cpm": 1e-9})";
  EXPECT_NE(load_error(R"({"format": "texel-document", "version": 2, )" + km_device +
                       R"(, "texture": {"kind": "reference", "name": "patch-2.5", "params": {"patch_mm": 0.001}}})")
                .find("patch_mm is 0.001 mm: up to"),
            std::string::npos);
  EXPECT_NE(load_error(R"({"format": "texel-document", "version": 2, )" + km_device +
                       R"(, "texture": {"kind": "reference", "name": "pulse-a", "params": {"pulse_mm": 0.001}}})")
                .find("pulse_mm is 0.001 mm: up to"),
            std::string::npos);
  // A 10^-6 cpm square wave on the tpad grid: 10^8 harmonics below Nyquist.
  EXPECT_NE(load_error(R"({"format": "texel-document", "version": 2, "device": "tpad",
      "texture": {"kind": "reference", "name": "square", "params": {"fundamental_cpm": 1e-6}}})")
                .find("fundamental_cpm is 1e-06 cpm"),
            std::string::npos);
  // The shipped lengths still prepare.
  EXPECT_EQ(load_error(R"({"format": "texel-document", "version": 2, "device": "tpad",
      "texture": {"kind": "reference", "name": "patch-4.6"}})"),
            "(no exception)");
}

TEST(Document, MalformedAndTruncatedJsonAreRejected) {
  EXPECT_NE(load_error("{ not json").find("malformed JSON"), std::string::npos);
  EXPECT_NE(load_error("").find("malformed JSON"), std::string::npos);
  EXPECT_NE(load_error("[1, 2]").find("must be a JSON object"), std::string::npos);
  // Every proper prefix of a valid document is an error, never a document.
  const std::string full = valid;
  for (std::size_t cut = 0; cut + 1 < full.size(); cut += 7)
    EXPECT_NE(load_error(full.substr(0, cut)), "(no exception)") << "accepted a document cut at " << cut;
}

TEST(Document, SaveIsAtomicAndLoadRoundTrips) {
  const texel::test_support::TempDir tmp("texel-doc");
  const fs::path& dir = tmp.path;
  const Document d = parse_document(valid, "doc");
  const std::string path = (dir / "t.texel.json").string();
  save_document(d, path);
  expect_same(d, load_document(path));
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u) << "a temporary file was left behind";
  try {
    load_document((dir / "missing.texel.json").string());
    ADD_FAILURE() << "loaded a missing file";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.texel.json"), std::string::npos);
  }
  fs::remove_all(dir);
}

TEST(Document, RendersLikeTheTextureItDescribes) {
  TexelSpec s;
  s.seed = 42;
  s.coarse = SineProfile{Millimetres(5.0), 0.0};
  s.coarse_strength = 0.3;
  const DeviceProfile tpad = load_device("tpad");
  const Surface surface = prepare_surface(make_document(tpad, s));
  const TexelTexture alone(s, tpad.length(), Sampling{tpad.grid(), tpad.band_top()});
  std::vector<double> want(static_cast<std::size_t>(tpad.samples));
  alone.render(tpad.grid(), 0, want);
  const auto got = surface.render();
  ASSERT_EQ(got.size(), want.size());
  EXPECT_EQ(std::memcmp(got.data(), want.data(), got.size() * sizeof(double)), 0);
  // And the document survives a round trip with the same samples.
  const Document back = parse_document(document_json(make_document(tpad, s)), "rt");
  EXPECT_EQ(prepare_surface(back).render(), got);
}
