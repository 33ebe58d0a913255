// Device profiles (device.hpp, docs/algorithm.md §8): built-ins, user profiles from
// a path and from TEXEL_DEVICE_PATH, validation naming the field, grid
// overrides, and the sample encoders (round(a·65535) for u16).
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "texel/device.hpp"
#include "texel/error.hpp"

using namespace texel;
namespace fs = std::filesystem;

namespace {

using texel::test_support::TempDir;

const char* const valid_profile = R"({
  "name": "bench-rig",
  "description": "a user profile",
  "samples": 1000,
  "spacing_mm": 0.01,
  "format": "u8",
  "refresh_hz": 5000
})";

std::string parse_error(const std::string& json) {
  return test_support::message_of<FormatError>([&] { parse_device_profile(json, "test.json"); });
}

/// valid_profile with one "key": value replaced or added.
std::string with_field(const std::string& key, const std::string& value) {
  std::string j = valid_profile;
  const auto at = j.find("\"" + key + "\"");
  if (at == std::string::npos) return j.substr(0, j.rfind('}')) + ", \"" + key + "\": " + value + "}";
  const auto colon = j.find(':', at);
  const auto end = j.find_first_of(",\n}", colon);
  return j.substr(0, colon + 1) + " " + value + j.substr(end);
}

}  // namespace

TEST(Device, BuiltinsLoad) {
  const auto names = builtin_device_names();
  for (const char* want : {"tpad", "tpad-tablet", "generic"})
    EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
  for (const auto& n : names) {
    const DeviceProfile d = load_device(n);
    EXPECT_EQ(d.name, n);
    EXPECT_NO_THROW(validate(d));
  }
}

TEST(Device, TpadIsTheReferenceDevice) {
  // docs/algorithm.md §8: 19,200 unsigned 16-bit values, one per 0.0053 mm.
  const DeviceProfile d = load_device("tpad");
  EXPECT_EQ(d.samples, 19200);
  EXPECT_EQ(d.spacing.value(), 0.0053);
  EXPECT_EQ(d.format, SampleFormat::u16le);
  EXPECT_EQ(d.native_bytes(), 38400u);
  EXPECT_NEAR(d.length().value(), 101.76, 1e-9);
  EXPECT_NEAR(d.band_top().value(), 94.33962264150944, 1e-12);
  EXPECT_EQ(d.band_min.value(), 0.01);
  ASSERT_EQ(d.layout.size(), 2u);  // the studies' left/right halves
  EXPECT_EQ(d.layout[0].name, "left");
  EXPECT_EQ(d.layout[1].start.value(), 50.88);
  EXPECT_EQ(d.grid().count, 19200);
}

TEST(Device, WithGridOverridesLengthAndSpacing) {
  const DeviceProfile g = with_grid(load_device("generic"), Millimetres(2000.0), Millimetres(0.005));
  EXPECT_EQ(g.samples, 400000);
  EXPECT_EQ(g.spacing.value(), 0.005);
  EXPECT_NEAR(g.band_top().value(), 100.0, 1e-12);
  const DeviceProfile t = with_grid(load_device("tpad"), Millimetres(50.0), std::nullopt);
  EXPECT_EQ(t.samples, std::llround(50.0 / 0.0053));
  EXPECT_TRUE(t.layout.empty() || t.layout.size() == 1) << "regions past the new end are dropped";
  EXPECT_LE(t.layout.size(), 1u);
  const DeviceProfile same = with_grid(load_device("tpad"), std::nullopt, std::nullopt);
  EXPECT_EQ(device_profile_json(same), device_profile_json(load_device("tpad")));
  EXPECT_THROW(with_grid(load_device("tpad"), Millimetres(0.0), std::nullopt), InvalidArgument);
  EXPECT_THROW(with_grid(load_device("tpad"), Millimetres(-5.0), std::nullopt), InvalidArgument);
  EXPECT_THROW(with_grid(load_device("tpad"), std::nullopt, Millimetres(0.0)), InvalidArgument);
  EXPECT_THROW(with_grid(load_device("tpad"), std::nullopt, Millimetres(NAN)), InvalidArgument);
}

TEST(Device, UserProfileFromAFile) {
  TempDir d;
  const auto path = d.write("rig.json", valid_profile);
  const DeviceProfile p = load_device(path);
  EXPECT_EQ(p.name, "bench-rig");
  EXPECT_EQ(p.samples, 1000);
  EXPECT_EQ(p.format, SampleFormat::u8);
  EXPECT_EQ(p.native_bytes(), 1000u);
  EXPECT_EQ(p.band_top().value(), 50.0);
}

TEST(Device, UserProfileFromTexelDevicePath) {
  TempDir d;
  fs::create_directories(d.path / "b");
  std::ofstream(d.path / "b" / "bench-rig.json") << valid_profile;
  const std::string dirs = (d.path / "a").string() + ":" + (d.path / "b").string();
  ASSERT_EQ(::setenv("TEXEL_DEVICE_PATH", dirs.c_str(), 1), 0);
  const DeviceProfile p = load_device("bench-rig");
  EXPECT_EQ(p.samples, 1000);
  ::unsetenv("TEXEL_DEVICE_PATH");
  EXPECT_THROW(load_device("bench-rig"), InvalidArgument);
}

TEST(Device, UnknownNameListsTheBuiltins) {
  try {
    load_device("no-such-device");
    FAIL() << "no error";
  } catch (const InvalidArgument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no-such-device"), std::string::npos) << m;
    EXPECT_NE(m.find("tpad"), std::string::npos) << m;
  }
}

TEST(Device, BadProfilesAreRejectedNamingTheField) {
  EXPECT_EQ(parse_error(valid_profile), "(no exception)");
  struct Case {
    std::string key, value, expect;
  };
  const Case cases[] = {
      {"samples", "0", "samples"},
      {"samples", "12.5", "samples"},
      {"spacing_mm", "-0.01", "spacing_mm"},
      {"spacing_mm", "\"fine\"", "spacing_mm"},
      {"format", "\"u12\"", "format"},
      {"refresh_hz", "0", "refresh_hz"},
      {"band_min_cpm", "0", "band_min_cpm"},
      {"band_max_cpm", "80", "band_max_cpm"},  // above the 50 cpm Nyquist of a 0.01 mm grid
      {"colour", "\"red\"", "unknown key 'colour'"},
      {"layout", "[{\"name\": \"x\", \"start_mm\": 5, \"length_mm\": 20}]", "layout region 'x'"},
  };
  for (const auto& c : cases) {
    const std::string msg = parse_error(with_field(c.key, c.value));
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.key << "=" << c.value << ": " << msg;
    EXPECT_NE(msg.find("test.json"), std::string::npos) << "errors name the origin: " << msg;
  }
  EXPECT_NE(parse_error("{\"name\": \"x\"").find("malformed JSON"), std::string::npos);
  EXPECT_NE(parse_error("{\"name\": \"x\"}").find("samples is missing"), std::string::npos);
}

TEST(Device, ProfileJsonRoundTrips) {
  for (const auto& n : builtin_device_names()) {
    const DeviceProfile a = load_device(n);
    const DeviceProfile b = parse_device_profile(device_profile_json(a), "round trip");
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.description, a.description);
    EXPECT_EQ(b.samples, a.samples);
    EXPECT_EQ(b.spacing.value(), a.spacing.value());
    EXPECT_EQ(b.format, a.format);
    EXPECT_EQ(b.refresh.value(), a.refresh.value());
    EXPECT_EQ(b.band_min.value(), a.band_min.value());
    EXPECT_EQ(b.band_max.value(), a.band_max.value());
    EXPECT_EQ(b.response.corner.value(), a.response.corner.value());
    EXPECT_EQ(b.response.order, a.response.order);
    EXPECT_EQ(b.response.source, a.response.source);
    ASSERT_EQ(b.layout.size(), a.layout.size());
    for (std::size_t i = 0; i < a.layout.size(); ++i) {
      EXPECT_EQ(b.layout[i].name, a.layout[i].name);
      EXPECT_EQ(b.layout[i].start.value(), a.layout[i].start.value());
      EXPECT_EQ(b.layout[i].length.value(), a.layout[i].length.value());
    }
  }
}

TEST(Device, FrequencyResponseIsOptionalAndValidated) {
  // Missing: flat (old and user profiles keep loading), and the JSON a flat
  // profile writes has no "response" (its text is unchanged).
  const DeviceProfile flat = parse_device_profile(valid_profile, "test.json");
  EXPECT_TRUE(flat.response.flat());
  EXPECT_EQ(flat.response.gain(Hertz(5000.0)), 1.0);
  EXPECT_EQ(device_profile_json(flat).find("response"), std::string::npos);
  EXPECT_TRUE(parse_device_profile(with_field("response", "null"), "test.json").response.flat());
  // Valid: corner and order, with a source; round trip.
  const DeviceProfile lp =
      parse_device_profile(with_field("response", R"({"corner_hz": 400, "order": 2, "source": "measured"})"), "test.json");
  EXPECT_EQ(lp.response.corner.value(), 400.0);
  EXPECT_EQ(lp.response.order, 2);
  EXPECT_EQ(lp.response.source, "measured");
  const DeviceProfile back = parse_device_profile(device_profile_json(lp), "round trip");
  EXPECT_EQ(back.response.corner.value(), 400.0);
  EXPECT_EQ(back.response.order, 2);
  EXPECT_EQ(back.response.source, "measured");
  // Invalid values name the field.
  struct Case {
    std::string value, expect;
  };
  const Case cases[] = {
      {R"({"corner_hz": 0, "order": 1})", "response.corner_hz"},
      {R"({"corner_hz": -5, "order": 1})", "response.corner_hz"},
      {R"({"corner_hz": 2e6, "order": 1})", "response.corner_hz"},
      {R"({"corner_hz": "fast", "order": 1})", "response.corner_hz"},
      {R"({"order": 1})", "response.corner_hz is missing"},
      {R"({"corner_hz": 400})", "response.order is missing"},
      {R"({"corner_hz": 400, "order": 0})", "response.order"},
      {R"({"corner_hz": 400, "order": 5})", "response.order"},
      {R"({"corner_hz": 400, "order": 1.5})", "response.order"},
      {R"({"corner_hz": 400, "order": 1, "q": 3})", "unknown key"},
      {R"(400)", "response must be a JSON object"},
  };
  for (const auto& c : cases) {
    const std::string msg = parse_error(with_field("response", c.value));
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.value << ": " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
  DeviceProfile bad = flat;
  bad.response.corner = Hertz(400.0);
  bad.response.order = 7;
  EXPECT_THROW(validate(bad), InvalidArgument);
}

TEST(Device, FrequencyResponseIsAButterworthMagnitude) {
  FrequencyResponse r;
  r.corner = Hertz(400.0);
  r.order = 1;
  EXPECT_NEAR(r.gain_db(Hertz(400.0)), -3.0103, 1e-3);  // −3 dB at the corner
  EXPECT_NEAR(r.gain(Hertz(40.0)), 1.0, 0.01);          // flat well below it
  EXPECT_NEAR(r.gain_db(Hertz(4000.0)), -20.04, 0.01);  // 6 dB/octave, 20 dB/decade above
  EXPECT_NEAR(r.gain_db(r.frequency_at_db(20.0)), -20.0, 1e-9);
  r.order = 2;
  EXPECT_NEAR(r.gain_db(Hertz(4000.0)), -40.0, 0.01);
  EXPECT_NEAR(r.gain_db(r.frequency_at_db(20.0)), -20.0, 1e-9);
  EXPECT_TRUE(std::isinf(FrequencyResponse{}.frequency_at_db(20.0).value()));
}

TEST(Device, BuiltinResponses) {
  // Ultrasonic friction displays are low-pass (docs/format.md, with sources
  // in each profile); the generic profile promises nothing: flat.
  for (const char* name : {"tpad", "tpad-tablet"}) {
    const DeviceProfile d = load_device(name);
    EXPECT_FALSE(d.response.flat()) << name;
    EXPECT_GT(d.response.corner.value(), 50.0) << name;
    EXPECT_LT(d.response.corner.value(), 2000.0) << name;
    EXPECT_FALSE(d.response.source.empty()) << name << ": a response states where its numbers come from";
  }
  EXPECT_TRUE(load_device("generic").response.flat());
}

TEST(Encode, U16IsRoundOfAmplitudeTimes65535) {
  EXPECT_EQ(to_u16(0.0), 0);
  EXPECT_EQ(to_u16(1.0), 65535);
  EXPECT_EQ(to_u16(0.5), 32768);  // 32767.5 rounds half up
  EXPECT_EQ(to_u16(1.0 / 65535.0), 1);
  EXPECT_EQ(to_u16(0.49 / 65535.0), 0);
  EXPECT_EQ(to_u16(-0.5), 0);  // clamped
  EXPECT_EQ(to_u16(2.0), 65535);
  EXPECT_EQ(to_u16(NAN), 0);
  // Little-endian bytes in the device stream.
  const double a[] = {0.0, 1.0, 0.5, 256.0 / 65535.0};
  std::byte out[8];
  encode_samples(SampleFormat::u16le, a, out);
  const unsigned char want[] = {0x00, 0x00, 0xFF, 0xFF, 0x00, 0x80, 0x00, 0x01};
  EXPECT_EQ(std::memcmp(out, want, 8), 0);
}

RC_GTEST_PROP(Encode, DecodeInvertsEncodeWithinHalfAStep, ()) {
  const auto format = *rc::gen::element(SampleFormat::u16le, SampleFormat::u8, SampleFormat::f32le, SampleFormat::f64le);
  const auto n = *rc::gen::inRange<std::size_t>(1, 3000);  // crosses the encoders' 1024-sample blocks
  std::vector<double> a(n);
  for (auto& v : a) v = *rc::gen::inRange(0, 1000001) / 1e6;
  std::vector<std::byte> bytes(n * bytes_per_sample(format) + 1);
  // Encode at an odd offset: the stream need not be aligned.
  encode_samples(format, a, std::span<std::byte>(bytes.data() + 1, bytes.size() - 1));
  const auto back = decode_samples(format, std::span<const std::byte>(bytes.data() + 1, bytes.size() - 1));
  RC_ASSERT(back.size() == n);
  const double tol = format == SampleFormat::u16le   ? 0.5 / 65535
                     : format == SampleFormat::u8    ? 0.5 / 255
                     : format == SampleFormat::f32le ? 1e-7
                                                     : 0.0;
  for (std::size_t i = 0; i < n; ++i) RC_ASSERT(std::fabs(back[i] - a[i]) <= tol + 1e-15);
}

TEST(Encode, DecodeRejectsAPartialSample) {
  const std::byte three[3] = {};
  EXPECT_THROW(decode_samples(SampleFormat::u16le, three), FormatError);
  EXPECT_THROW(parse_sample_format("s16"), InvalidArgument);
  EXPECT_EQ(parse_sample_format("f32le"), SampleFormat::f32le);
}
