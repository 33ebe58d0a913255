// Reference generators: parameters, determinism, patch and pulse layouts,
// documents holding references.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/reference.hpp"

using namespace texel;

namespace {
const Grid tpad{Millimetres(0.0), Millimetres(0.0053), 19200};

ReferenceSpec spec(const std::string& name, std::uint64_t seed = 1) {
  ReferenceSpec s;
  s.name = name;
  s.seed = seed;
  return s;
}
}  // namespace

TEST(ReferenceCatalogue, HasEveryFamilyAndTheNineFirstStudyPairs) {
  for (const char* n : {"2sin", "3sin", "4sin", "white", "pink", "blue", "square", "tri", "saw", "patch-2.5", "patch-4.6",
                        "patch-13.5", "pulse-a", "pulse-b", "bandpass"})
    EXPECT_NO_THROW(reference_info(n)) << n;
  for (const char* fc : {"1", "4", "20"})
    for (const char* z : {"0.05", "0.5", "5"}) EXPECT_NO_THROW(reference_info(std::string("bandpass-f") + fc + "-z" + z));
  EXPECT_THROW(reference_info("5sin"), InvalidArgument);
}

TEST(ReferenceParams, ValidatesKeysRangesAndKinds) {
  ReferenceSpec s = spec("4sin");
  EXPECT_NO_THROW(set_reference_param(s, "frequencies_cpm=1,2,3"));
  EXPECT_EQ(std::get<std::vector<double>>(s.params.at("frequencies_cpm")).size(), 3u);
  EXPECT_THROW(set_reference_param(s, "frequency=1"), InvalidArgument);          // unknown key
  EXPECT_THROW(set_reference_param(s, "frequencies_cpm=1,x"), InvalidArgument);  // not a number
  EXPECT_THROW(set_reference_param(s, "frequencies_cpm=-1"), InvalidArgument);   // out of range
  EXPECT_THROW(set_reference_param(s, "phase=sometimes"), InvalidArgument);      // not a choice
  EXPECT_THROW(set_reference_param(s, "novalue"), InvalidArgument);
  ReferenceSpec p = spec("patch-2.5");
  EXPECT_THROW(set_reference_param(p, "shuffle=1.5"), InvalidArgument);  // integer
  ReferenceSpec w = spec("2sin");
  w.params["weights"] = std::vector<double>{1, 2, 3};
  EXPECT_THROW(validate(w), InvalidArgument);  // one weight per frequency
  // A frequency at or above Nyquist is an error, not silent aliasing.
  ReferenceSpec hi = spec("2sin");
  set_reference_param(hi, "frequencies_cpm=2.5,100");
  EXPECT_THROW(ReferenceTexture(hi, Millimetres(10), Sampling{tpad}), InvalidArgument);
}

TEST(ReferenceDeterminism, SameSeedSameBytesAnyWindow) {
  for (const char* n : {"pink", "bandpass-f4-z0.5", "patch-4.6"}) {
    const auto a = render_reference(spec(n, 7), tpad);
    const auto b = render_reference(spec(n, 7), tpad);
    EXPECT_EQ(a, b) << n;  // exact
    const auto c = render_reference(spec(n, 8), tpad);
    EXPECT_NE(a, c) << n;
    // A window rendered on its own equals the same samples of the whole (exact).
    const ReferenceTexture t(spec(n, 7), tpad.length(), Sampling{tpad});
    const Grid other{Millimetres(0.0), Millimetres(0.0053), 19200};
    std::vector<double> w(777);
    // Evaluate without the cache (different origin object, same values) and compare.
    const Grid shifted{Millimetres(1e-300), Millimetres(0.0053),
                       19200};  // not bit-equal: forces evaluation; positions round to the same doubles
    t.render(shifted, 5000, w);
    for (std::size_t i = 0; i < w.size(); ++i) EXPECT_EQ(w[i], a[5000 + i]) << n << " " << i;
    (void)other;
  }
}

TEST(ReferenceAmplitude, SignalReferencesSpanTheFullRange) {
  // a = 0.5 + 0.5·y/max|y|: min or max reaches the end of [0, 1] (to 1e-12).
  for (const char* n : {"4sin", "white", "saw", "bandpass-f1-z0.05"}) {
    const auto a = render_reference(spec(n), tpad);
    const auto [lo, hi] = std::minmax_element(a.begin(), a.end());
    EXPECT_GE(*lo, 0.0);
    EXPECT_LE(*hi, 1.0);
    EXPECT_TRUE(std::abs(*lo) < 1e-12 || std::abs(*hi - 1.0) < 1e-12) << n;
  }
}

TEST(ReferenceScalar, KernelMatchesSlowEvaluation) {
  // The vector kernel against the scalar amplitude_at, bit for bit.
  const ReferenceTexture t(spec("3sin"), tpad.length(), Sampling{tpad});
  std::vector<double> a(19200);
  t.render(tpad, 0, a);
  for (std::int64_t i = 0; i < 19200; i += 37) EXPECT_EQ(a[static_cast<std::size_t>(i)], t.amplitude_at(tpad.position(i)));
}

TEST(PatchTexture, GapStatisticsAsSpecified) {
  // Gaps are whole mm in {0 … round(2c)}; over 200 seeds the mean gap is c
  // within 3 standard errors, and every value of the support occurs.
  for (const auto& [name, c] : std::map<std::string, double>{{"patch-2.5", 2.5}, {"patch-13.5", 13.5}}) {
    const int top = static_cast<int>(std::lround(2 * c));
    std::vector<double> all;
    for (std::uint64_t seed = 1; seed <= 200; ++seed) {
      const ReferenceTexture t(spec(name, seed), Millimetres(1000.0),
                               Sampling{Grid{Millimetres(0.0), Millimetres(0.01), 100000}});
      for (const auto& f : t.features()) EXPECT_NEAR(f.length.value(), 2.6, 1e-12);
      for (const Millimetres gap : t.gaps()) {
        const double g = gap.value();
        EXPECT_NEAR(g, std::round(g), 1e-9);
        EXPECT_GE(g, -1e-9);
        EXPECT_LE(g, top + 1e-9);
        all.push_back(std::round(g));
      }
    }
    const double mean = std::accumulate(all.begin(), all.end(), 0.0) / all.size();
    const double sd = std::sqrt(((top + 1.0) * (top + 1.0) - 1.0) / 12.0);  // discrete uniform
    EXPECT_NEAR(mean, c, 3 * sd / std::sqrt(all.size())) << name;
    for (int v = 0; v <= top; ++v) EXPECT_GT(std::count(all.begin(), all.end(), v), 0) << name << " gap " << v;
  }
  // c = 4.6: support {0 … 9} [choice], mean 4.5.
  const ReferenceTexture t(spec("patch-4.6"), Millimetres(5000.0), Sampling{Grid{Millimetres(0.0), Millimetres(0.05), 100000}});
  for (const Millimetres g : t.gaps()) EXPECT_LE(g.value(), 9 + 1e-9);
}

TEST(PatchTexture, ShufflesPreserveTheGapMultiset) {
  const ReferenceTexture base(spec("patch-13.5", 3), Millimetres(101.76), Sampling{tpad});
  auto g0 = base.gaps();
  ASSERT_GE(g0.size(), 3u);
  int differing = 0;
  for (int k = 1; k <= 64; ++k) {
    ReferenceSpec s = spec("patch-13.5", 3);
    s.params["shuffle"] = double(k);
    const ReferenceTexture t(s, Millimetres(101.76), Sampling{tpad});
    auto g = t.gaps();
    ASSERT_EQ(g.size(), g0.size());
    differing += g != g0;
    auto a = g0, b = g;
    for (auto& x : a) x = Millimetres(std::round(x.value() * 1e6));
    for (auto& x : b) x = Millimetres(std::round(x.value() * 1e6));
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b) << "shuffle " << k;  // identical multiset (to 1 nm)
  }
  EXPECT_GT(differing, 32);  // shuffles actually reorder
}

TEST(PulsePair, MirrorImagesDifferentSignals) {
  const auto a = render_reference(spec("pulse-a"), tpad);
  const auto b = render_reference(spec("pulse-b"), tpad);
  // b(x) = a(L − x): on the grid, b[i] = a[(N − i) mod N] (within 1e-9).
  const std::size_t n = a.size();
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(b[i], a[(n - i) % n], 1e-9);
  double diff = 0;
  for (std::size_t i = 0; i < n; ++i) diff = std::max(diff, std::abs(a[i] - b[i]));
  EXPECT_GT(diff, 0.5);  // different signals
}

TEST(ReferenceDocument, ReferenceLeftTexelRightOnOneMap) {
  const std::string json = R"({
    "format": "texel-document", "version": 2, "device": "tpad",
    "regions": [
      {"name": "left", "start_mm": 0, "length_mm": 50.88,
       "texture": {"kind": "reference", "name": "4sin", "seed": 1, "params": {"phase": "zero"}}},
      {"name": "right", "start_mm": 50.88,
       "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 1}}
    ]})";
  const Document doc = parse_document(json);
  const auto map = prepare_surface(doc).render();
  ASSERT_EQ(map.size(), 19200u);
  // Left half: exactly the reference rendered over 50.88 mm on the same grid.
  const ReferenceTexture ref(doc.regions[0].reference.value(), Millimetres(50.88),
                             Sampling{Grid{Millimetres(0.0), Millimetres(0.0053), 19200}});
  std::vector<double> left(9600);
  ref.render(Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, 0, left);
  for (std::size_t i = 0; i < 9600; ++i) ASSERT_EQ(map[i], left[i]) << i;
  // Right half: exactly the Texel rendering of the right region alone.
  Document right = make_document(doc.device, doc.regions[1].texel);
  right.regions[0].start = Millimetres(50.88);
  const auto rmap = prepare_surface(right).render();
  for (std::size_t i = 9600; i < 19200; ++i) ASSERT_EQ(map[i], rmap[i]) << i;
  // Round trip: written as version 2, parsed back to the same map.
  const std::string text = document_json(doc);
  EXPECT_NE(text.find("\"version\": 2"), std::string::npos);
  EXPECT_EQ(prepare_surface(parse_document(text)).render(), map);
}

TEST(ReferenceDocument, ReferenceAsCoarseProfile) {
  const std::string json = R"({
    "format": "texel-document", "version": 2, "device": "tpad",
    "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 1,
                "coarse_strength": 1, "fine_strength": 0,
                "coarse": {"kind": "reference", "name": "pulse-a"}}})";
  const Document doc = parse_document(json);
  ASSERT_TRUE(doc.regions[0].coarse_reference.has_value());
  const Surface s = prepare_surface(doc);
  const auto map = s.render();
  const auto pulses = render_reference(spec("pulse-a"), tpad);
  // C = 1, F = 0: the map is the coarse profile c_k, i.e. the pulse sampled at
  // texel centres (0.25 mm texels): within 0.02 of the pulse everywhere.
  double worst = 0;
  for (std::size_t i = 0; i < map.size(); ++i) worst = std::max(worst, std::abs(map[i] - pulses[i]));
  EXPECT_LT(worst, 0.1);  // a texel is 1/20 of the 5 mm pulse: |Δc| <= π/20·… < 0.1
  EXPECT_EQ(prepare_surface(parse_document(document_json(doc))).render(), map);
}

TEST(ReferenceDocument, TexelOnlyDocumentsStayVersion1AndBadReferencesAreNamed) {
  const Document d = make_document(load_device("tpad"), TexelSpec{});
  EXPECT_NE(document_json(d).find("\"version\": 1"), std::string::npos);
  const std::string bad = R"({"format": "texel-document", "version": 2, "device": "tpad",
    "texture": {"kind": "reference", "name": "4sin", "params": {"frequencies_cpm": [2.5, -1]}}})";
  try {
    parse_document(bad);
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("frequencies_cpm[1]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_document(R"({"format": "texel-document", "version": 2, "device": "tpad",
    "texture": {"kind": "reference", "name": "4sin", "extra": 1}})"),
               FormatError);
}
