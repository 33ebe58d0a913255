// Reference generators: parameters, determinism, patch and pulse layouts,
// documents holding references.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "../support/grids.hpp"
#include "../support/specs.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/reference.hpp"

using namespace texel;

namespace {
const Grid tpad = test_support::tpad_grid();

ReferenceSpec spec(const std::string& name, std::uint64_t seed = 1) { return test_support::reference_spec(name, seed); }
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
  const ReferenceTexture ref(doc.regions[0].reference.value(), Millimetres(50.88), Sampling{tpad});
  std::vector<double> left(9600);
  ref.render(tpad, 0, left);
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

TEST(ReferenceSynthesis, ChirpZAgreesWithTheDirectSum) {
  // Version 3's chirp-z synthesis and version 2's direct sum are the same
  // function: on the tpad grid the amplitudes agree within 5e-12 (measured up
  // to 2.1e-12, nearly all of it the direct sum's own rounding of f·x at
  // phases up to 10^4 cycles; see the next test); sums of sinusoids and
  // amplitude-defined references are the same bits.
  for (const char* n : {"white", "pink", "blue", "bandpass-f1-z0.05", "bandpass-f4-z0.5", "bandpass-f20-z5", "square", "tri",
                        "saw", "4sin", "patch-4.6", "pulse-a"}) {
    ReferenceSpec d = spec(n, 9);
    d.synthesis = ReferenceSynthesis::direct;
    const ReferenceSpec c = spec(n, 9);
    ASSERT_EQ(c.synthesis, ReferenceSynthesis::chirp_z);  // the default
    const ReferenceTexture td(d, tpad.length(), Sampling{tpad});
    const ReferenceTexture tc(c, tpad.length(), Sampling{tpad});
    EXPECT_NEAR(tc.peak(), td.peak(), 1e-12 * td.peak()) << n;
    std::vector<double> a(19200), b(19200);
    td.render(tpad, 0, a);
    tc.render(tpad, 0, b);
    double worst = 0;
    for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
    EXPECT_LT(worst, 5e-12) << n;
    const ReferenceInfo& info = reference_info(n);
    if (info.family == "sum of sinusoids" || info.family == "patch texture" || info.family == "coarse pulse pair")
      EXPECT_EQ(a, b) << n;
    else
      EXPECT_NE(a, b) << n;  // the last bits differ: why the format version changes
  }
}

TEST(ReferenceSynthesis, ChirpZIsWithin1e13OfALongDoubleSum) {
  // The slow, obviously-correct reference: the same components summed in long
  // double at exact harmonic frequencies (k/L for noise, n·f0 for waveforms),
  // every 97th sample of the tpad grid. Measured: chirp-z ~1e-15, the direct
  // double sum ~2e-12.
  const long double two_pi = 2.0L * 3.14159265358979323846264338327950288L;
  for (const char* n : {"white", "blue", "saw", "tri"}) {
    const ReferenceTexture t(spec(n, 2), tpad.length(), Sampling{tpad});
    const bool noise = reference_info(n).uses_seed;
    const long double period = tpad.length().value();
    std::vector<double> a(19200);
    t.render(tpad, 0, a);
    double worst = 0;
    for (std::int64_t i = 0; i < 19200; i += 97) {
      const long double x = static_cast<long double>(i) * tpad.spacing.value();
      long double y = 0;
      for (const auto& c : t.components()) {
        const long double f = noise ? std::round(c.frequency.value() * period) / period : std::round(c.frequency.value());
        long double u = c.phase_cycles + f * x;
        u -= std::floor(u);
        y += c.amplitude * std::sin(two_pi * u);
      }
      const long double v = std::clamp(0.5L + 0.5L * y / t.peak(), 0.0L, 1.0L);
      worst = std::max(worst, static_cast<double>(std::abs(v - a[static_cast<std::size_t>(i)])));
    }
    EXPECT_LT(worst, 1e-13) << n;
  }
}

TEST(ReferenceSynthesis, AnyWindowAndAnyGridGiveTheWholesValues) {
  // A region right of 50.88 mm (texture coordinates: origin −50.88 mm): windows
  // straddling the texture's edges give the whole map's bytes, positions
  // outside [0, L) are at rest, and sample(x) on a grid sample is the cached
  // value even though the chirp-z synthesis is not evaluated pointwise.
  const Grid local{Millimetres(-50.88), Millimetres(0.0053), 19200};
  const ReferenceTexture t(spec("white", 4), Millimetres(30.0), Sampling{local});
  std::vector<double> whole(19200);
  t.render(local, 0, whole);
  for (const auto& [first, len] : std::vector<std::pair<std::int64_t, std::size_t>>{
           {9500, 300}, {15000, 400}, {0, 19200}, {9601, 7}, {0, 100}, {18000, 500}}) {
    std::vector<double> w(len);
    t.render(local, first, w);
    for (std::size_t i = 0; i < len; ++i) ASSERT_EQ(w[i], whole[static_cast<std::size_t>(first) + i]) << first << " + " << i;
  }
  std::size_t inside = 0;
  for (std::int64_t i = 0; i < 19200; ++i) {
    const double x = local.position(i).value();
    if (x < 0.0 || x >= 30.0) {
      ASSERT_EQ(whole[static_cast<std::size_t>(i)], 0.0) << i;
    } else {
      ++inside;
      if (i % 101 == 0) {
        ASSERT_EQ(t.sample(Millimetres(x)), whole[static_cast<std::size_t>(i)]) << i;
      }
    }
  }
  EXPECT_GT(inside, 5600u);
  // Between grid samples: the direct sum, the same function to 1e-12.
  ReferenceSpec d = spec("white", 4);
  d.synthesis = ReferenceSynthesis::direct;
  const ReferenceTexture td(d, Millimetres(30.0), Sampling{local});
  for (double x = 0.001; x < 30.0; x += 0.77) EXPECT_NEAR(t.sample(Millimetres(x)), td.sample(Millimetres(x)), 1e-12) << x;
}

TEST(ReferenceSynthesis, TooManyHarmonicsAreRefusedBeforeAllocating) {
  // 100 m of full-band white noise at 5 µm: 10^7 harmonics, over the chirp-z
  // limit (about 768 MiB of FFT buffers at 2^22); the message names the band.
  const Grid fine{Millimetres(0.0), Millimetres(0.005), 0};
  try {
    (void)ReferenceTexture(spec("white"), Millimetres(100000.0), Sampling{fine});
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("harmonics"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("narrow the band"), std::string::npos) << e.what();
  }
}

TEST(ReferenceDocument, VersionPicksTheSynthesisAndIsKeptWhenWritten) {
  const auto doc_text = [](int version) {
    return R"({"format": "texel-document", "version": )" + std::to_string(version) + R"(, "device": "tpad",
      "regions": [
        {"start_mm": 0, "length_mm": 50.88, "texture": {"kind": "reference", "name": "pink", "seed": 3}},
        {"start_mm": 50.88, "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5,
          "texel_length_mm": 0.25, "seed": 1, "coarse_strength": 1, "coarse": {"kind": "reference", "name": "saw"}}}]})";
  };
  std::vector<double> maps[4];
  for (int version : {2, 3}) {
    const Document doc = parse_document(doc_text(version));
    const ReferenceSynthesis want = version == 2 ? ReferenceSynthesis::direct : ReferenceSynthesis::chirp_z;
    EXPECT_EQ(doc.regions[0].reference->synthesis, want);
    EXPECT_EQ(doc.regions[1].coarse_reference->synthesis, want);
    EXPECT_EQ(required_version(doc), version);
    // Written back with its own version, and re-read to the same bytes.
    const std::string text = document_json(doc);
    EXPECT_NE(text.find("\"version\": " + std::to_string(version)), std::string::npos) << text;
    maps[version] = prepare_surface(doc).render();
    EXPECT_EQ(prepare_surface(parse_document(text)).render(), maps[version]);
    // The left region is exactly the reference with that synthesis.
    ReferenceSpec ref = spec("pink", 3);
    ref.synthesis = want;
    const ReferenceTexture t(ref, Millimetres(50.88), Sampling{tpad});
    std::vector<double> left(9600);
    t.render(tpad, 0, left);
    for (std::size_t i = 0; i < left.size(); ++i) ASSERT_EQ(maps[version][i], left[i]) << version << " " << i;
  }
  EXPECT_NE(maps[2], maps[3]);
  // A version-1 document that holds a reference (accepted before version 2
  // existed) keeps the direct bytes, and is written as version 2.
  const Document v1 = parse_document(doc_text(1));
  EXPECT_EQ(prepare_surface(v1).render(), maps[2]);
  EXPECT_EQ(required_version(v1), 2);
  // New documents take the current synthesis and say so.
  const Document fresh = make_reference_document(load_device("tpad"), spec("white"));
  EXPECT_EQ(Document::current_version, 6);  // 6: multi-channel playback (docs/rendering.md)
  EXPECT_NE(document_json(fresh).find("\"version\": 3"), std::string::npos);
  // One document, one synthesis: a mix cannot be written.
  Document mixed = parse_document(doc_text(2));
  mixed.regions[1].coarse_reference->synthesis = ReferenceSynthesis::chirp_z;
  EXPECT_THROW((void)document_json(mixed), InvalidArgument);
  // Version 4 does not exist yet.
  EXPECT_THROW(parse_document(doc_text(4)), FormatError);
}
