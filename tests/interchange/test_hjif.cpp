// MPEG-I Haptics interchange (texel/interchange.hpp, docs/interchange.md):
// export -> import round trips (exact through the carried parameters, within
// the tolerance through the samples alone), conformance of the written JSON
// checked here independently of the reader, every class of malformed input
// refused with a one-line error, and the glTF container's structure.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/json_mutation.hpp"
#include "../support/specs.hpp"
#include "../support/temp_dir.hpp"
#include "interchange_support.hpp"
#include "texel/bitstream.hpp"
#include "texel/codec.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/io.hpp"
#include "texel/random.hpp"
#include "texel/signal.hpp"
#include "texel/surface.hpp"

using namespace texel;
using nlohmann::json;
using texel::test_support::TempDir;

namespace {

TexelSpec fine(double pitch_db, double irregularity_db, double length_mm, std::uint64_t seed) {
  return test_support::fine_spec(pitch_db, irregularity_db, length_mm, seed);
}

struct Case {
  std::string name;
  Document doc;
  bool transcodable;
};

/// Fine-only, coarse, quantized, two-region and reference documents. `shift`
/// lowers every Central Pitch (dB) for coarse grids whose band ends lower.
std::vector<Case> cases(const DeviceProfile& device, double shift = 0.0) {
  std::vector<Case> out;
  out.push_back({"fine", make_document(device, fine(10 + shift, -5, 0.25, 7)), true});
  TexelSpec coarse = fine(8 + shift, -8, 0.5, 3);
  coarse.coarse = SineProfile{Millimetres(5.0), 0.0};
  coarse.coarse_strength = 0.6;
  coarse.fine_strength = 0.4;
  out.push_back({"coarse", make_document(device, coarse), true});
  TexelSpec quantized = fine(12 + shift, -3, 0.25, 11);
  quantized.quantization_db = 3.0;
  out.push_back({"quantized", make_document(device, quantized), true});
  const Document regions = test_support::two_region_document(device, shift);
  out.push_back({"regions", regions, false});
  if (shift == 0.0) {  // 4sin's components reach 11 cpm
    ReferenceSpec ref;
    ref.name = "4sin";
    out.push_back({"reference", make_reference_document(device, ref), false});
  }
  return out;
}

hjif::ExportOptions options() {
  hjif::ExportOptions o;
  o.date = "2026-01-02";
  return o;
}

/// The text with the carried document removed: the samples alone.
std::string without_carried(const std::string& text) {
  json j = json::parse(text);
  j["description"] = "stripped";
  return j.dump();
}

double max_error(const hjif::Experience& e, const Document& doc) { return test_support::max_map_error(e, doc); }

// --- conformance, checked here from the format's rules (not by the reader) ---

void expect_conformant(const std::string& text, const Document& doc, const std::string& modality) {
  const json j = json::parse(text);
  ASSERT_TRUE(j.is_object());
  for (const char* key : {"version", "profile", "level", "date", "description", "timescale", "avatars", "perceptions", "syncs"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_TRUE(std::regex_match(j["version"].get<std::string>(), std::regex("^[0-9]{4}(-[0-9])?$")));
  EXPECT_GE(std::stoi(j["version"].get<std::string>().substr(0, 4)), 2023);
  EXPECT_EQ(j["profile"], "Main");
  ASSERT_TRUE(j["level"].is_number_integer());
  EXPECT_EQ(j["level"], 1);
  // RFC 3339 date-time (the schema's format), UTC.
  EXPECT_TRUE(std::regex_match(j["date"].get<std::string>(),
                               std::regex("^[0-9]{4}-[01][0-9]-[0-3][0-9]T[0-2][0-9]:[0-5][0-9]:[0-5][0-9]Z$")));
  ASSERT_TRUE(j["timescale"].is_number_unsigned());
  EXPECT_GE(j["timescale"].get<std::uint64_t>(), 1u);
  EXPECT_LE(j["timescale"].get<std::uint64_t>(), 48000u);  // Main profile
  EXPECT_TRUE(j["avatars"].is_array());
  EXPECT_TRUE(j["syncs"].is_array());
  ASSERT_TRUE(j["perceptions"].is_array());
  EXPECT_EQ(j["perceptions"].size(), doc.regions.size());  // one perception per region
  std::set<std::int64_t> ids;
  for (const json& p : j["perceptions"]) {
    EXPECT_TRUE(ids.insert(p["id"].get<std::int64_t>()).second) << "perception ids are unique";
    EXPECT_EQ(p["avatar_id"], 0);
    EXPECT_TRUE(p["description"].is_string());
    EXPECT_EQ(p["perception_modality"], modality);
    EXPECT_EQ(p["unit_exponent"], -3);  // millimetres
    EXPECT_TRUE(p["effect_library"].is_array());
    ASSERT_EQ(p["reference_devices"].size(), 1u);
    EXPECT_EQ(p["reference_devices"][0]["id"], 1);  // the schema counts reference devices from 1
    ASSERT_EQ(p["channels"].size(), 1u);            // one channel (level 1: ≤ 128)
    const json& c = p["channels"][0];
    for (const char* key : {"id", "description", "gain", "mixing_coefficient", "body_part_mask", "bands"})
      EXPECT_TRUE(c.contains(key)) << key;
    EXPECT_TRUE(c["gain"].is_number());
    EXPECT_EQ(c["reference_device_id"], 1);
    EXPECT_TRUE(c["body_part_mask"].is_number_unsigned());
    ASSERT_EQ(c["bands"].size(), 1u);  // level 1: ≤ 7
    const json& b = c["bands"][0];
    EXPECT_EQ(b["band_type"], "Curve");
    EXPECT_EQ(b["curve_type"], "Linear");
    ASSERT_TRUE(b["lower_frequency_limit"].is_number_integer());
    ASSERT_TRUE(b["upper_frequency_limit"].is_number_integer());
    EXPECT_LE(b["lower_frequency_limit"].get<std::int64_t>(), b["upper_frequency_limit"].get<std::int64_t>());
    ASSERT_EQ(b["effects"].size(), 1u);
    const json& e = b["effects"][0];
    EXPECT_EQ(e["effect_type"], "Basis");
    EXPECT_TRUE(e["position"].is_number_integer());
    EXPECT_TRUE(e["phase"].is_number());
    EXPECT_EQ(e["base_signal"], "Sine");
    ASSERT_TRUE(e["keyframes"].is_array());
    ASSERT_FALSE(e["keyframes"].empty());
    std::int64_t last = -1;
    for (const json& k : e["keyframes"]) {
      ASSERT_TRUE(k["relative_position"].is_number_integer());  // integer positions
      const auto rel = k["relative_position"].get<std::int64_t>();
      EXPECT_GT(rel, last);  // strictly increasing
      last = rel;
      ASSERT_TRUE(k["amplitude_modulation"].is_number());
      EXPECT_GE(k["amplitude_modulation"].get<double>(), 0.0);
      EXPECT_LE(k["amplitude_modulation"].get<double>(), 1.0);
      EXPECT_FALSE(k.contains("frequency_modulation"));
    }
    EXPECT_EQ(e["keyframes"][0]["relative_position"], 0);
  }
  EXPECT_TRUE(hjif::conformance_errors(text).empty());
}

TEST(Hjif, ExportIsConformantAndRoundTripsExactlyThroughTheCarriedParameters) {
  const DeviceProfile tpad = load_device("tpad");
  for (const Case& c : cases(tpad)) {
    SCOPED_TRACE(c.name);
    const hjif::Exported x = hjif::export_hjif(c.doc, options());
    expect_conformant(x.json, c.doc, "Friction");
    EXPECT_LE(x.stats.max_error, hjif::default_tolerance);
    EXPECT_EQ(x.stats.timescale, 10000u);  // 0.0053 mm = 53 ticks
    EXPECT_TRUE(x.stats.grid_on_ticks);

    const hjif::Experience e = hjif::parse_hjif(x.json, c.name);
    ASSERT_TRUE(e.carried.has_value()) << e.carried_rejected;
    EXPECT_EQ(document_json(*e.carried), document_json(c.doc));
    EXPECT_EQ(prepare_surface(*e.carried).render_native(tpad.format), prepare_surface(c.doc).render_native(tpad.format));
    if (c.transcodable) {
      EXPECT_EQ(codec::transcode(*e.carried).bytes, codec::transcode(c.doc).bytes);
    }
    EXPECT_LE(max_error(e, c.doc), hjif::default_tolerance);
    EXPECT_DOUBLE_EQ(max_error(hjif::parse_hjif(without_carried(x.json), c.name), c.doc), x.stats.max_error);
  }
}

TEST(Hjif, SamplesAloneReproduceTheMapWithinTheToleranceOnTpadAndGenericGrids) {
  // tpad: the test above (the curves are the same with or without the carried document).
  for (const char* device : {"generic", "tpad-tablet"}) {
    const DeviceProfile d = load_device(device);
    for (const Case& c : cases(d, std::string(device) == "tpad-tablet" ? -8.0 : 0.0)) {
      SCOPED_TRACE(std::string(device) + " " + c.name);
      const hjif::Exported x = hjif::export_hjif(c.doc, options());
      const hjif::Experience e = hjif::parse_hjif(without_carried(x.json), c.name);
      EXPECT_FALSE(e.carried.has_value());
      const double err = max_error(e, c.doc);
      EXPECT_LE(err, hjif::default_tolerance);
      EXPECT_DOUBLE_EQ(err, x.stats.max_error);  // the exporter measured what the importer sees
    }
  }
}

TEST(Hjif, AWiderToleranceNeedsFewerKeyframesAndIsKept) {
  const DeviceProfile tpad = load_device("tpad");
  TexelSpec coarse = fine(4, -8, 0.5, 3);
  coarse.coarse = SineProfile{Millimetres(10.0), 0.0};
  coarse.coarse_strength = 1.0;
  coarse.fine_strength = 0.0;  // a bare coarse map: long straight stretches
  const Document doc = make_document(tpad, coarse);
  hjif::ExportOptions tight = options();
  hjif::ExportOptions loose = options();
  loose.tolerance = 0.05;
  const auto a = hjif::export_hjif(doc, tight);
  const auto b = hjif::export_hjif(doc, loose);
  EXPECT_LT(b.stats.keyframes, a.stats.keyframes);
  EXPECT_LT(a.stats.keyframes, static_cast<std::size_t>(tpad.samples) / 4);  // far fewer than samples
  EXPECT_LE(b.stats.max_error, 0.05);
  EXPECT_GT(b.stats.max_error, hjif::default_tolerance);  // the budget is used
  EXPECT_LE(max_error(hjif::parse_hjif(without_carried(b.json)), doc), 0.05);
  hjif::ExportOptions bad = options();
  for (double t : {0.0, -1.0, 0.6, std::nan("")}) {
    bad.tolerance = t;
    EXPECT_THROW((void)hjif::export_hjif(doc, bad), InvalidArgument) << t;
  }
  bad = options();
  bad.date = "yesterday";
  EXPECT_THROW((void)hjif::export_hjif(doc, bad), InvalidArgument);
}

TEST(Hjif, AGridOffTheTicksIsWrittenAtTheNearestTickAndStillMeetsTheTolerance) {
  const DeviceProfile odd = with_grid(load_device("generic"), Millimetres(10.0), Millimetres(0.00471239));
  const Document doc = make_document(odd, fine(10, -5, 0.25, 7));
  const hjif::Exported x = hjif::export_hjif(doc, options());
  EXPECT_FALSE(x.stats.grid_on_ticks);
  EXPECT_EQ(x.stats.timescale, 48000u);
  EXPECT_LE(x.stats.max_error, hjif::default_tolerance);
  const hjif::Experience e = hjif::parse_hjif(without_carried(x.json));
  EXPECT_LE(max_error(e, doc), hjif::default_tolerance);
  EXPECT_TRUE(hjif::conformance_errors(x.json).empty());
}

TEST(Hjif, ModalityIsWrittenAsTheStandardSpellsIt) {
  const DeviceProfile tpad = load_device("tpad");
  hjif::ExportOptions o = options();
  o.modality = hjif::parse_modality("vibrotactile-texture");
  const Document doc = make_document(tpad, fine(10, -5, 0.25, 7));
  expect_conformant(hjif::export_hjif(doc, o).json, doc, "Vibrotactile Texture");
  EXPECT_THROW((void)hjif::parse_modality("tickle"), InvalidArgument);
}

TEST(Hjif, TheSignalLoaderAndTheTranscoderReadHjifFiles) {
  TempDir dir("hjif-loader");
  const DeviceProfile tpad = load_device("tpad");
  const Document doc = make_document(tpad, fine(10, -5, 0.25, 7));
  const std::string path = dir.write("a.hjif", hjif::export_hjif(doc, options()).json);
  const std::vector<double> map = prepare_surface(doc).render();

  // Samples: the carried document's device grid, within the tolerance.
  const Signal s = codec::load_signal(path);
  EXPECT_EQ(s.format, SignalFormat::hjif);
  ASSERT_EQ(s.samples.size(), map.size());
  EXPECT_DOUBLE_EQ(s.spacing.value(), tpad.spacing.value());
  for (std::size_t i = 0; i < map.size(); ++i) ASSERT_NEAR(s.samples[i], map[i], hjif::default_tolerance) << i;

  // Samples alone: the reference device named in the file gives the grid.
  const std::string bare = dir.write("bare.hjif", without_carried(read_file(path)));
  const Signal b = codec::load_signal(bare);
  EXPECT_EQ(b.samples.size(), map.size());
  // Another grid on request.
  SignalOptions at;
  at.spacing = Millimetres(0.01);
  EXPECT_NEAR(static_cast<double>(codec::load_signal(bare, at).samples.size()), tpad.length().value() / 0.01, 1.0);

  // The exact path: the same bitstream as the document itself.
  std::string why;
  const auto t = codec::transcode_file(path, {}, {}, &why);
  ASSERT_TRUE(t.has_value()) << why;
  EXPECT_EQ(t->bytes, codec::transcode(doc).bytes);
  EXPECT_TRUE(t->exact);
  EXPECT_FALSE(codec::transcode_file(bare, {}, {}, &why).has_value());
  EXPECT_NE(why.find("samples"), std::string::npos);
}

TEST(Hjif, ACarriedDocumentThatDisagreesWithTheCurvesIsNotUsed) {
  const DeviceProfile tpad = load_device("tpad");
  const Document doc = make_document(tpad, fine(10, -5, 0.25, 7));
  json j = json::parse(hjif::export_hjif(doc, options()).json);
  auto& k = j["perceptions"][0]["channels"][0]["bands"][0]["effects"][0]["keyframes"][100]["amplitude_modulation"];
  k = k.get<double>() > 0.5 ? 0.1 : 0.9;
  const hjif::Experience e = hjif::parse_hjif(j.dump());
  EXPECT_FALSE(e.carried.has_value());
  EXPECT_NE(e.carried_rejected.find("away from the file's curves"), std::string::npos) << e.carried_rejected;

  json other = json::parse(hjif::export_hjif(doc, options()).json);
  std::string d = other["description"];
  d.replace(d.find("\"version\""), 9, "\"versoin\"");
  other["description"] = d;
  const hjif::Experience f = hjif::parse_hjif(other.dump());
  EXPECT_FALSE(f.carried.has_value());
  EXPECT_NE(f.carried_rejected.find("carried"), std::string::npos);
}

// --- a file from elsewhere ---------------------------------------------------

json minimal(const std::string& modality = "Friction") {
  return json::parse(R"({"version":"2023","profile":"Main","level":1,"date":"2024-05-06T00:00:00Z","description":"hand made",
    "timescale":1000,"avatars":[],"syncs":[],
    "perceptions":[{"id":0,"avatar_id":0,"description":"p","perception_modality":")" +
                     modality + R"(",
      "unit_exponent":-3,"effect_library":[],
      "channels":[{"id":0,"description":"c","gain":1.0,"mixing_coefficient":1.0,"body_part_mask":0,
        "bands":[{"band_type":"Curve","curve_type":"Linear","lower_frequency_limit":0,"upper_frequency_limit":10,
          "effects":[{"effect_type":"Basis","position":1000,"phase":0,"base_signal":"Sine",
            "keyframes":[{"relative_position":0,"amplitude_modulation":0.0},
                         {"relative_position":2000,"amplitude_modulation":1.0},
                         {"relative_position":4000,"amplitude_modulation":0.5}]}]}]}]}]})");
}

TEST(Hjif, LinearCurvesAreEvaluatedAsTheFormatDefinesThem) {
  const hjif::Experience e = hjif::parse_hjif(minimal().dump());
  // 1000 ticks per mm; keyframes at 1, 3, 5 mm.
  const std::vector<double> x{0.0, 0.999, 1.0, 2.0, 3.0, 4.0, 5.0, 5.001, 6.0};
  const std::vector<double> want{0.0, 0.0, 0.0, 0.5, 1.0, 0.75, 0.5, 0.0, 0.0};
  const auto got = hjif::evaluate(e, x);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-12) << x[i];
  // Through the loader on a spacing (no device named): 0 … 5 mm.
  TempDir dir("hjif-foreign");
  const std::string path = dir.write("f.hjif", minimal().dump());
  SignalOptions o;
  o.spacing = Millimetres(0.5);
  const Signal s = load_signal(path, o);
  EXPECT_EQ(s.samples.size(), 11u);
  EXPECT_NEAR(s.samples[4], 0.5, 1e-12);
  // Without a grid: a one-line FieldError naming the option.
  try {
    (void)load_signal(path);
    FAIL();
  } catch (const FieldError& err) {
    EXPECT_EQ(err.field(), "device");
  }
}

TEST(Hjif, TemporalVibrotactilePerceptionsNeedASwipeSpeed) {
  TempDir dir("hjif-temporal");
  json j = minimal("Vibrotactile");
  j["perceptions"][0].erase("unit_exponent");
  j["perceptions"][0]["channels"][0]["frequency_sampling"] = 8000;
  const std::string path = dir.write("t.hjif", j.dump());
  try {
    (void)load_signal(path);
    FAIL();
  } catch (const FieldError& err) {
    EXPECT_EQ(err.field(), "swipe_speed");
  }
  SignalOptions o;
  o.swipe_speed = MmPerSecond(100.0);
  const Signal s = load_signal(path, o);
  EXPECT_NEAR(s.spacing.value(), 100.0 / 8000.0, 1e-15);
  EXPECT_TRUE(s.scaled);  // like a recording
  ASSERT_TRUE(s.sample_rate.has_value());
  // 1000 ticks per second: keyframes at 1, 3, 5 s = 100, 300, 500 mm.
  EXPECT_NEAR(s.length().value(), 500.0 + s.spacing.value(), 1e-6);
}

// --- malformed inputs: one line each -------------------------------------------

TEST(Hjif, MalformedFilesAreRefusedWithOneLineNamingTheField) {
  // `reader`: a piece of parse_hjif's one-line message (nullptr: the reader
  // accepts the file); `checker`: conformance_errors reports it (the schemas,
  // their field dependencies and the reference software's rules).
  struct Bad {
    const char* what;
    std::string text;
    const char* reader;
    bool checker;
  };
  std::vector<Bad> bad;
  auto with = [](auto edit) {
    json j = minimal();
    edit(j);
    return j.dump();
  };
  auto band = [](json& j) -> json& { return j["perceptions"][0]["channels"][0]["bands"][0]; };
  auto kf = [&](json& j) -> json& { return band(j)["effects"][0]["keyframes"]; };
  // Refused by the schema: by both.
  bad.push_back({"not JSON", "{\"version\":", "malformed JSON", true});
  bad.push_back({"array root", "[]", "must be a JSON object", true});
  bad.push_back({"missing version", with([](json& j) { j.erase("version"); }), "version is missing", true});
  bad.push_back({"wrong type", with([](json& j) { j["level"] = "one"; }), "level must be a whole number", true});
  bad.push_back({"version", with([](json& j) { j["version"] = "2023-10"; }), "version is '2023-10'", true});
  bad.push_back({"date", with([](json& j) { j["date"] = "last tuesday"; }), "date is 'last tuesday'", true});
  bad.push_back({"impossible date", with([](json& j) { j["date"] = "2023-02-29"; }), "date is '2023-02-29'", true});
  bad.push_back({"control characters", with([](json& j) { j["version"] = "20\n23"; }), "'20\\x0a23'", true});
  bad.push_back({"long string", with([](json& j) { j["version"] = std::string(100000, '7'); }), "7…'", true});
  bad.push_back({"modality", with([](json& j) { j["perceptions"][0]["perception_modality"] = "Tickle"; }), "'Tickle'", true});
  bad.push_back({"perceptions type", with([](json& j) { j["perceptions"] = 5; }), "perceptions must be an array", true});
  bad.push_back({"no perceptions", with([](json& j) { j["perceptions"] = json::array(); }), "at least 1 perception", true});
  bad.push_back(
      {"no channels", with([](json& j) { j["perceptions"][0]["channels"] = json::array(); }), "at least 1 channel", true});
  bad.push_back({"device id 0",
                 with([](json& j) { j["perceptions"][0]["reference_devices"] = json::parse(R"([{"id":0,"name":"tpad"}])"); }),
                 "reference_devices[0].id is 0; allowed: >= 1", true});
  bad.push_back({"negative gain", with([](json& j) { j["perceptions"][0]["channels"][0]["gain"] = -1.0; }), "gain is -1", true});
  bad.push_back({"negative position", with([&](json& j) { band(j)["effects"][0]["position"] = -5; }), "position is -5", true});
  bad.push_back({"phase", with([&](json& j) { band(j)["effects"][0]["phase"] = 7; }), "phase is 7", true});
  bad.push_back({"block length", with([&](json& j) { band(j)["block_length"] = 8; }), "block_length is 8", true});
  bad.push_back({"vector",
                 with([](json& j) { j["perceptions"][0]["channels"][0]["direction"] = json::parse(R"({"X":128,"Y":0,"Z":0})"); }),
                 "direction.X is 128", true});
  bad.push_back(
      {"frequency", with([&](json& j) { band(j)["upper_frequency_limit"] = 20000; }), "upper_frequency_limit is 20000", true});
  bad.push_back(
      {"amplitude", with([&](json& j) { kf(j)[1]["amplitude_modulation"] = 1.5; }), "amplitude_modulation is 1.5", true});
  bad.push_back({"fractional position", with([&](json& j) { kf(j)[1]["relative_position"] = 2000.5; }), "whole number", true});
  bad.push_back({"band type", with([&](json& j) { band(j)["band_type"] = "Wavelet"; }), "band_type is 'Wavelet'", true});
  bad.push_back({"spelling", with([&](json& j) { band(j)["curve_type"] = "Bspline"; }), "curve_type is 'Bspline'", true});
  bad.push_back({"huge array", with([&](json& j) {
                   json many = json::array();
                   for (int i = 0; i < 70000; ++i) many.push_back(json::object());
                   j["avatars"] = many;
                 }),
                 "at most 65536 are read", true});
  std::string deep = "{\"version\":";
  for (int i = 0; i < 200; ++i) deep += "[";
  bad.push_back({"deep nesting", deep, "nests JSON deeper than 32", true});
  // The checker's strict reading (RFC 3339, the reference software's loader and profile rules): read all the same.
  bad.push_back({"space date", with([](json& j) { j["date"] = "2026-11-26 14:06:29"; }), nullptr, true});
  bad.push_back({"day", with([](json& j) { j["date"] = "2026-11-26"; }), nullptr, true});
  bad.push_back({"no timescale", with([](json& j) { j.erase("timescale"); }), nullptr, true});
  bad.push_back({"level", with([](json& j) { j["level"] = 3; }), nullptr, true});
  bad.push_back({"profile", with([](json& j) { j["profile"] = "Deluxe"; }), nullptr, true});
  bad.push_back({"timescale", with([](json& j) { j["timescale"] = 96000; }), nullptr, true});
  bad.push_back({"simple timescale", with([](json& j) {
                   j["profile"] = "Simple Parametric";
                   j["timescale"] = 10000;
                 }),
                 nullptr, true});
  bad.push_back({"simple modality", with([](json& j) { j["profile"] = "Simple Parametric"; }), nullptr, true});
  bad.push_back({"duplicate id", with([](json& j) { j["perceptions"].push_back(j["perceptions"][0]); }), nullptr, true});
  bad.push_back({"avatar", with([](json& j) { j["perceptions"][0]["avatar_id"] = 4; }), nullptr, true});
  bad.push_back(
      {"dangling device", with([](json& j) { j["perceptions"][0]["channels"][0]["reference_device_id"] = 2; }), nullptr, true});
  bad.push_back({"frequency limits", with([&](json& j) { band(j)["lower_frequency_limit"] = 20; }), nullptr, true});
  bad.push_back({"channels at level 1", with([](json& j) {
                   json c = j["perceptions"][0]["channels"][0];
                   for (int i = 1; i <= 128; ++i) c["id"] = i, j["perceptions"][0]["channels"].push_back(c);
                 }),
                 nullptr, true});
  bad.push_back({"bands at level 1", with([&](json& j) {
                   json b = band(j);
                   for (int i = 0; i < 7; ++i) j["perceptions"][0]["channels"][0]["bands"].push_back(b);
                 }),
                 nullptr, true});
  bad.push_back({"basis without keyframes",
                 with([&](json& j) { band(j)["effects"].push_back(json::parse(R"({"effect_type":"Basis"})")); }), nullptr, true});
  // Optional in the schema: defaults apply, for both.
  bad.push_back({"no phase, id, base signal", with([&](json& j) {
                   for (const char* k : {"phase", "base_signal", "id"}) band(j)["effects"][0].erase(k);
                 }),
                 nullptr, false});
  bad.push_back({"no position", with([&](json& j) { band(j)["effects"][0].erase("position"); }), nullptr, false});
  bad.push_back({"no syncs", with([](json& j) { j.erase("syncs"); }), nullptr, false});
  // Conformant, but not what Texel samples: refused by the reader only.
  bad.push_back({"order", with([&](json& j) { kf(j)[2]["relative_position"] = 1000; }), "not after the previous", false});
  bad.push_back({"missing amplitude", with([&](json& j) { kf(j)[0].erase("amplitude_modulation"); }),
                 "amplitude_modulation is missing", false});
  bad.push_back({"curve type", with([&](json& j) { band(j)["curve_type"] = "Cubic"; }), "curve_type 'Linear'", false});
  bad.push_back({"curve type on a transient band", with([&](json& j) { band(j)["band_type"] = "Transient"; }),
                 "band_type is 'Transient'", true});
  bad.push_back({"reference effect", with([&](json& j) {
                   auto& e = band(j)["effects"][0];
                   e["effect_type"] = "Reference";
                   e["id"] = 3;
                 }),
                 "is 'Reference'", true});
  bad.push_back({"no sampled perception", with([](json& j) { j["perceptions"][0]["perception_modality"] = "Temperature"; }),
                 "no perception Texel can sample", false});

  for (const Bad& b : bad) {
    SCOPED_TRACE(b.what);
    try {
      (void)hjif::parse_hjif(b.text, "x.hjif");
      EXPECT_EQ(b.reader, nullptr) << "accepted";
    } catch (const FormatError& e) {
      const std::string m = e.what();
      ASSERT_NE(b.reader, nullptr) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      EXPECT_NE(m.find(b.reader), std::string::npos) << m;
      EXPECT_NE(m.find("x.hjif"), std::string::npos) << m;
    }
    const auto errors = hjif::conformance_errors(b.text);
    EXPECT_EQ(!errors.empty(), b.checker) << (errors.empty() ? "" : errors.front());
    for (const auto& e : errors) EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  // The keyframe cap: counted before anything per keyframe is kept.
  hjif::ImportLimits small;
  small.max_keyframes = 2;
  EXPECT_THROW((void)hjif::parse_hjif(minimal().dump(), "x.hjif", small), FormatError);
}

// The fuzz target's contract over generated mutations of its seed corpus (the
// GCC side of fuzz_hjif; docs/fuzzing.md): only texel::Error escapes, and an
// accepted file samples to finite values.
TEST(Hjif, MutatedFilesAreAcceptedOrRefusedWithATexelError) {
  const std::string dir = std::string(TEXEL_TEST_SOURCE_DIR) + "/tests/fuzz/corpus/fuzz_hjif/";
  const CounterRng rng(12, 0);
  std::size_t accepted = 0;
  std::size_t refused = 0;
  for (const char* seed : {"exported-friction.hjif", "hand-friction.hjif", "hand-temporal.hjif", "exported-two-regions.hjif"}) {
    const std::string text = read_file(dir + seed);
    for (std::uint64_t k = 0; k < 600; ++k) {
      std::string m = texel::test_support::mutate_json(text, rng, k);
      if (k % 3 == 0) m = texel::test_support::mutate_json(m, rng, k + 1000000);
      try {
        (void)hjif::conformance_errors(m);
        SignalOptions o;
        o.swipe_speed = MmPerSecond(100.0);
        o.spacing = Millimetres(0.05);
        o.max_samples = 1 << 16;
        const Signal s = decode_signal(std::as_bytes(std::span(m.data(), m.size())), SignalFormat::hjif, o, "m.hjif");
        for (double a : s.samples) ASSERT_TRUE(a >= 0.0 && a <= 1.0) << seed << " mutation " << k;
        ++accepted;
      } catch (const Error&) {
        ++refused;
      } catch (const std::exception& e) {
        FAIL() << seed << " mutation " << k << ": " << e.what();
      }
    }
  }
  EXPECT_GT(accepted, 0u);
  EXPECT_GT(refused, 0u);
}

// --- glTF ----------------------------------------------------------------------

std::uint32_t le32(const std::vector<std::byte>& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | std::to_integer<std::uint32_t>(b[at + static_cast<std::size_t>(i)]);
  return v;
}

TEST(Gltf, TheAssetCarriesTheMpegHapticMaterialAndAQuadTheSizeOfTheDisplay) {
  const DeviceProfile tpad = load_device("tpad");
  const Document doc = make_document(tpad, fine(10, -5, 0.25, 7));
  gltf::AssetOptions o;
  o.hjif_uri = "a.hjif";
  const auto text = gltf::asset(doc, o, gltf::Container::gltf);
  const json j = json::parse(std::string(reinterpret_cast<const char*>(text.data()), text.size()));
  EXPECT_EQ(j["asset"]["version"], "2.0");
  const auto used = j["extensionsUsed"].get<std::vector<std::string>>();
  for (const char* e : {"MPEG_media", "MPEG_haptic", "MPEG_haptic_material"})
    EXPECT_NE(std::find(used.begin(), used.end(), e), used.end()) << e;
  EXPECT_EQ(j["extensions"]["MPEG_media"]["media"][0]["alternatives"][0]["uri"], "a.hjif");
  const json& m = j["extensions"]["MPEG_haptic_material"]["materials"][0];
  EXPECT_EQ(m["friction"][0]["type"], "High_Resolution");
  EXPECT_EQ(m["friction"][1]["type"], "Reference");
  EXPECT_EQ(j["meshes"][0]["extensions"]["MPEG_haptic_material"]["hapticMaterialIndex"], 0);
  EXPECT_NEAR(j["accessors"][0]["max"][0].get<double>(), tpad.length().value() / 1000.0, 1e-6);  // metres

  const auto glb = gltf::asset(doc, o, gltf::Container::glb);
  ASSERT_GE(glb.size(), 28u);
  EXPECT_EQ(le32(glb, 0), 0x46546C67u);
  EXPECT_EQ(le32(glb, 4), 2u);
  EXPECT_EQ(le32(glb, 8), glb.size());
  EXPECT_EQ(le32(glb, 12) % 4, 0u);
  EXPECT_EQ(le32(glb, 16), 0x4E4F534Au);

  o.hjif_uri.clear();
  EXPECT_THROW((void)gltf::asset(doc, o, gltf::Container::gltf), InvalidArgument);
}

TEST(Gltf, ThePngRowHoldsTheMapAsSixteenBitGrey) {
  const std::vector<double> a{0.0, 0.5, 1.0, 0.25};
  const auto png = gltf::png_row16(a);
  const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  ASSERT_GT(png.size(), 8u + 25u);
  EXPECT_EQ(std::memcmp(png.data(), sig, 8), 0);
  auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | std::to_integer<std::uint32_t>(png[at + static_cast<std::size_t>(i)]);
    return v;
  };
  EXPECT_EQ(be32(16), 4u);                       // width
  EXPECT_EQ(be32(20), 1u);                       // height
  EXPECT_EQ(std::to_integer<int>(png[24]), 16);  // bit depth
  // IDAT: zlib header, one stored block, the row (filter 0, big-endian samples).
  const std::size_t idat = 8 + 25;
  EXPECT_EQ(std::memcmp(png.data() + idat + 4, "IDAT", 4), 0);
  const std::size_t row = idat + 8 + 2 + 5;
  const std::vector<int> want{0, 0x00, 0x00, 0x80, 0x00, 0xFF, 0xFF, 0x40, 0x00};
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(std::to_integer<int>(png[row + i]), want[i]) << i;
  EXPECT_THROW((void)gltf::png_row16({}), InvalidArgument);
}

}  // namespace
