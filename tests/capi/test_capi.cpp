// The C ABI (include/texel.h): every function with valid and invalid
// arguments, and rendered values equal to the C++ library's. The same header
// is exercised from C99 by test_capi_c.c; byte equality with the `texel`
// command is in test_capi_cli.cpp.
#include "texel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"
#include "texel/codec.hpp"
#include "texel/device.hpp"
#include "texel/document.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/reference.hpp"
#include "texel/signal.hpp"
#include "texel/spectrum.hpp"
#include "texel/surface.hpp"

namespace {

using texel::test_support::TempDir;

constexpr double nan_v = std::numeric_limits<double>::quiet_NaN();

struct DocDel {
  void operator()(texel_document* d) const { texel_document_destroy(d); }
};
struct SurfDel {
  void operator()(texel_surface* s) const { texel_surface_destroy(s); }
};
struct EncDel {
  void operator()(texel_encode_result* r) const { texel_encode_result_destroy(r); }
};
struct PlayerDel {
  void operator()(texel_player* p) const { texel_player_destroy(p); }
};
using Doc = std::unique_ptr<texel_document, DocDel>;
using Surf = std::unique_ptr<texel_surface, SurfDel>;
using Enc = std::unique_ptr<texel_encode_result, EncDel>;
using Play = std::unique_ptr<texel_player, PlayerDel>;

texel_params study_params() {
  texel_params p = texel_params_default();
  p.central_pitch_db = 10;
  p.irregularity_db = -5;
  p.texel_length_mm = 0.25;
  p.seed = 7;
  return p;
}

Surf make_surface(const texel_params& p, const char* device = "tpad") {
  texel_surface* s = nullptr;
  EXPECT_EQ(texel_surface_from_params(device, &p, &s), TEXEL_OK) << texel_last_error();
  return Surf(s);
}

std::vector<double> cpp_map(const texel::TexelSpec& spec, const char* device = "tpad") {
  return texel::prepare_surface(texel::make_document(texel::load_device(device), spec)).render();
}

texel::TexelSpec study_spec() {
  texel::TexelSpec s;
  s.central_pitch = texel::Decibels(10);
  s.irregularity = texel::Decibels(-5);
  s.texel_length = texel::Millimetres(0.25);
  s.seed = 7;
  return s;
}

// Expects `status` and a non-empty message containing `fragment`.
#define EXPECT_FAILS(call, status, fragment)                                                                           \
  do {                                                                                                                 \
    EXPECT_EQ((call), (status)) << texel_last_error();                                                                 \
    EXPECT_NE(std::string(texel_last_error()).find(fragment), std::string::npos) << "message: " << texel_last_error(); \
  } while (0)

// ----------------------------------------------------------------- basics

TEST(CApi, VersionMatchesHeader) {
  int major = -1, minor = -1, patch = -1;
  texel_version(&major, &minor, &patch);
  EXPECT_EQ(major, TEXEL_VERSION_MAJOR);
  EXPECT_EQ(minor, TEXEL_VERSION_MINOR);
  EXPECT_EQ(patch, TEXEL_VERSION_PATCH);
  EXPECT_EQ(std::string(texel_version_string()),
            std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(patch));
  texel_version(nullptr, nullptr, nullptr);  // any pointer may be NULL
}

TEST(CApi, StatusStrings) {
  EXPECT_STREQ(texel_status_string(TEXEL_OK), "TEXEL_OK");
  EXPECT_STREQ(texel_status_string(TEXEL_INVALID_ARGUMENT), "TEXEL_INVALID_ARGUMENT");
  EXPECT_STREQ(texel_status_string(TEXEL_FORMAT_ERROR), "TEXEL_FORMAT_ERROR");
  EXPECT_STREQ(texel_status_string(TEXEL_IO_ERROR), "TEXEL_IO_ERROR");
  EXPECT_STREQ(texel_status_string(TEXEL_BUFFER_TOO_SMALL), "TEXEL_BUFFER_TOO_SMALL");
  EXPECT_STREQ(texel_status_string(TEXEL_OUT_OF_MEMORY), "TEXEL_OUT_OF_MEMORY");
  EXPECT_STREQ(texel_status_string(TEXEL_INTERNAL), "TEXEL_INTERNAL");
  EXPECT_STREQ(texel_status_string(static_cast<texel_status>(99)), "unknown status");
  EXPECT_STREQ(texel_status_string(static_cast<texel_status>(-1)), "unknown status");
}

TEST(CApi, LastErrorIsClearedBySuccessAndIsThreadLocal) {
  texel_device_info info{};
  EXPECT_FAILS(texel_device_lookup("no-such-device", &info), TEXEL_INVALID_ARGUMENT, "no-such-device");
  std::string other;
  std::thread([&] { other = texel_last_error(); }).join();
  EXPECT_EQ(other, "");  // another thread sees its own (empty) slot
  EXPECT_EQ(texel_device_lookup("tpad", &info), TEXEL_OK);
  EXPECT_STREQ(texel_last_error(), "");
}

// ---------------------------------------------------------------- devices

TEST(CApi, DeviceLookup) {
  texel_device_info info{};
  ASSERT_EQ(texel_device_lookup("tpad", &info), TEXEL_OK) << texel_last_error();
  const texel::DeviceProfile d = texel::load_device("tpad");
  EXPECT_EQ(info.samples, d.samples);
  EXPECT_EQ(info.samples, 19200);
  EXPECT_DOUBLE_EQ(info.spacing_mm, d.spacing.value());
  EXPECT_DOUBLE_EQ(info.length_mm, d.length().value());
  EXPECT_DOUBLE_EQ(info.refresh_hz, d.refresh.value());
  EXPECT_EQ(info.format, TEXEL_SAMPLE_U16LE);
  EXPECT_EQ(info.bytes_per_sample, 2u);

  EXPECT_FAILS(texel_device_lookup(nullptr, &info), TEXEL_INVALID_ARGUMENT, "device is NULL");
  EXPECT_FAILS(texel_device_lookup("tpad", nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
  EXPECT_FAILS(texel_device_lookup("nope", &info), TEXEL_INVALID_ARGUMENT, "tpad");  // lists the known names
}

TEST(CApi, DeviceFromProfileFile) {
  TempDir dir("capi");
  const std::string path = dir.write("dev.json", texel::device_profile_json(texel::load_device("generic")));
  texel_device_info info{};
  ASSERT_EQ(texel_device_lookup(path.c_str(), &info), TEXEL_OK) << texel_last_error();
  EXPECT_EQ(info.samples, texel::load_device("generic").samples);
  const std::string bad = dir.write("bad.json", "{ not json");
  EXPECT_NE(texel_device_lookup(bad.c_str(), &info), TEXEL_OK);
  EXPECT_STRNE(texel_last_error(), "");
}

// ------------------------------------------------------------- parameters

TEST(CApi, ParamsDefaultsAreTheLibrarys) {
  const texel_params p = texel_params_default();
  const texel::TexelSpec s;
  EXPECT_EQ(p.central_pitch_db, s.central_pitch.value());
  EXPECT_EQ(p.irregularity_db, s.irregularity.value());
  EXPECT_EQ(p.texel_length_mm, s.texel_length.value());
  EXPECT_EQ(p.seed, s.seed);
  EXPECT_EQ(p.parameterization, TEXEL_PARAMETERIZATION_MOMENTS);
  EXPECT_EQ(p.quantization_db, 0.0);
  EXPECT_EQ(p.coarse_strength, 0.0);
  EXPECT_EQ(p.fine_strength, 1.0);
  EXPECT_EQ(p.coarse_sine_period_mm, 0.0);
  EXPECT_EQ(p.coarse_sine_phase_deg, 0.0);
}

TEST(CApi, BadParamsNameTheField) {
  struct Case {
    void (*mutate)(texel_params&);
    const char* field;
  };
  const Case cases[] = {
      {[](texel_params& p) { p.central_pitch_db = nan_v; }, "central_pitch_db"},
      {[](texel_params& p) { p.irregularity_db = INFINITY; }, "irregularity_db"},
      {[](texel_params& p) { p.texel_length_mm = nan_v; }, "texel_length_mm"},
      {[](texel_params& p) { p.texel_length_mm = 0; }, "texel_length_mm"},
      {[](texel_params& p) { p.texel_length_mm = -1; }, "texel_length_mm"},
      {[](texel_params& p) { p.quantization_db = -1; }, "quantization_db"},
      {[](texel_params& p) { p.quantization_db = 21; }, "quantization_db"},
      {[](texel_params& p) { p.quantization_db = nan_v; }, "quantization_db"},
      {[](texel_params& p) { p.coarse_strength = 1.5; }, "coarse_strength"},
      {[](texel_params& p) { p.coarse_strength = nan_v; }, "coarse_strength"},
      {[](texel_params& p) { p.fine_strength = -0.1; }, "fine_strength"},
      {[](texel_params& p) { p.coarse_sine_period_mm = -2; }, "coarse_sine_period_mm"},
      {[](texel_params& p) { p.coarse_sine_period_mm = nan_v; }, "coarse_sine_period_mm"},
      {[](texel_params& p) { p.coarse_sine_phase_deg = nan_v; }, "coarse_sine_phase_deg"},
      {[](texel_params& p) { p.parameterization = static_cast<texel_parameterization>(7); }, "parameterization"},
      {[](texel_params& p) { p.parameterization = static_cast<texel_parameterization>(-1); }, "parameterization"},
  };
  for (const Case& c : cases) {
    texel_params p = texel_params_default();
    c.mutate(p);
    texel_surface* s = reinterpret_cast<texel_surface*>(&p);  // must be reset to NULL
    EXPECT_FAILS(texel_surface_from_params("tpad", &p, &s), TEXEL_INVALID_ARGUMENT, c.field);
    EXPECT_EQ(s, nullptr);
    texel_document* d = reinterpret_cast<texel_document*>(&p);
    EXPECT_FAILS(texel_document_from_params("tpad", &p, &d), TEXEL_INVALID_ARGUMENT, c.field);
    EXPECT_EQ(d, nullptr);
  }
}

// -------------------------------------------------------------- documents

TEST(CApi, DocumentFromParamsRoundTripsThroughJson) {
  const texel_params p = study_params();
  texel_document* raw = nullptr;
  ASSERT_EQ(texel_document_from_params("tpad", &p, &raw), TEXEL_OK) << texel_last_error();
  Doc doc(raw);

  std::size_t needed = 0;
  ASSERT_EQ(texel_document_json(doc.get(), nullptr, 0, &needed), TEXEL_OK);
  const std::string expected = texel::document_json(texel::make_document(texel::load_device("tpad"), study_spec()));
  EXPECT_EQ(needed, expected.size() + 1);  // with the NUL

  std::vector<char> small(needed - 1, 'x');
  std::size_t needed2 = 0;
  EXPECT_FAILS(texel_document_json(doc.get(), small.data(), small.size(), &needed2), TEXEL_BUFFER_TOO_SMALL,
               std::to_string(needed));
  EXPECT_EQ(needed2, needed);
  EXPECT_EQ(small[0], 'x');  // nothing written

  std::vector<char> text(needed);
  ASSERT_EQ(texel_document_json(doc.get(), text.data(), text.size(), nullptr), TEXEL_OK);
  EXPECT_EQ(std::string(text.data()), expected);

  texel_document* parsed = nullptr;
  ASSERT_EQ(texel_document_parse(text.data(), needed - 1, &parsed), TEXEL_OK) << texel_last_error();
  Doc again(parsed);
  texel_surface *a = nullptr, *b = nullptr;
  ASSERT_EQ(texel_surface_create(doc.get(), &a), TEXEL_OK);
  ASSERT_EQ(texel_surface_create(again.get(), &b), TEXEL_OK);
  Surf sa(a), sb(b);
  std::vector<double> ma(19200), mb(19200);
  ASSERT_EQ(texel_surface_render(a, 0, ma.data(), ma.size()), TEXEL_OK);
  ASSERT_EQ(texel_surface_render(b, 0, mb.data(), mb.size()), TEXEL_OK);
  EXPECT_EQ(ma, mb);

  EXPECT_FAILS(texel_document_json(nullptr, text.data(), text.size(), &needed), TEXEL_INVALID_ARGUMENT, "doc is NULL");
  EXPECT_FAILS(texel_document_json(doc.get(), nullptr, 0, nullptr), TEXEL_INVALID_ARGUMENT, "both NULL");
}

TEST(CApi, DocumentParseAndLoadErrors) {
  texel_document* d = nullptr;
  const std::string bad = "{ \"format\": ";
  EXPECT_FAILS(texel_document_parse(bad.data(), bad.size(), &d), TEXEL_FORMAT_ERROR, "json");
  EXPECT_EQ(d, nullptr);
  const std::string wrong = R"({"format": "something-else", "version": 1})";
  EXPECT_FAILS(texel_document_parse(wrong.data(), wrong.size(), &d), TEXEL_FORMAT_ERROR, "format");
  EXPECT_FAILS(texel_document_parse(nullptr, 3, &d), TEXEL_INVALID_ARGUMENT, "json is NULL");
  EXPECT_FAILS(texel_document_parse(bad.data(), bad.size(), nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
  EXPECT_NE(texel_document_parse("", 0, &d), TEXEL_OK);

  EXPECT_FAILS(texel_document_load("/nonexistent/dir/map.texel.json", &d), TEXEL_IO_ERROR, "/nonexistent/dir/map.texel.json");
  EXPECT_EQ(d, nullptr);
  EXPECT_FAILS(texel_document_load(nullptr, &d), TEXEL_INVALID_ARGUMENT, "path is NULL");
  EXPECT_FAILS(texel_document_load("x", nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");

  TempDir dir("capi");
  const std::string path = dir.write("bad.texel.json", "[1, 2");
  EXPECT_EQ(texel_document_load(path.c_str(), &d), TEXEL_FORMAT_ERROR);

  const texel_params p = texel_params_default();
  EXPECT_FAILS(texel_document_from_params(nullptr, &p, &d), TEXEL_INVALID_ARGUMENT, "device is NULL");
  EXPECT_FAILS(texel_document_from_params("tpad", nullptr, &d), TEXEL_INVALID_ARGUMENT, "params is NULL");
  EXPECT_FAILS(texel_document_from_params("nope", &p, &d), TEXEL_INVALID_ARGUMENT, "nope");
  EXPECT_FAILS(texel_document_from_params("tpad", &p, nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
}

TEST(CApi, DocumentLoadFromFile) {
  TempDir dir("capi");
  const std::string path = dir.at("map.texel.json");
  texel::save_document(texel::make_document(texel::load_device("tpad"), study_spec()), path);
  texel_document* d = nullptr;
  ASSERT_EQ(texel_document_load(path.c_str(), &d), TEXEL_OK) << texel_last_error();
  Doc doc(d);
  texel_surface* s = nullptr;
  ASSERT_EQ(texel_surface_create(d, &s), TEXEL_OK);
  Surf surf(s);
  std::vector<double> m(19200);
  ASSERT_EQ(texel_surface_render(s, 0, m.data(), m.size()), TEXEL_OK);
  EXPECT_EQ(m, cpp_map(study_spec()));
}

TEST(CApi, Reference) {
  texel_document* d = nullptr;
  ASSERT_EQ(texel_document_from_reference("tpad", "4sin", 3, &d), TEXEL_OK) << texel_last_error();
  Doc doc(d);
  texel_surface* s = nullptr;
  ASSERT_EQ(texel_surface_create(d, &s), TEXEL_OK);
  Surf surf(s);
  texel::ReferenceSpec spec;
  spec.name = "4sin";
  spec.seed = 3;
  const auto expected = texel::prepare_surface(texel::make_reference_document(texel::load_device("tpad"), spec)).render();
  std::vector<double> m(expected.size());
  ASSERT_EQ(texel_surface_render(s, 0, m.data(), m.size()), TEXEL_OK);
  EXPECT_EQ(m, expected);

  EXPECT_FAILS(texel_document_from_reference("tpad", "no-such-reference", 1, &d), TEXEL_INVALID_ARGUMENT, "no-such-reference");
  EXPECT_EQ(d, nullptr);
  EXPECT_FAILS(texel_document_from_reference("tpad", nullptr, 1, &d), TEXEL_INVALID_ARGUMENT, "name is NULL");
  EXPECT_FAILS(texel_document_from_reference(nullptr, "4sin", 1, &d), TEXEL_INVALID_ARGUMENT, "device is NULL");
  EXPECT_FAILS(texel_document_from_reference("tpad", "4sin", 1, nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
}

// --------------------------------------------------------------- surfaces

TEST(CApi, RenderEqualsTheLibrary) {
  const Surf s = make_surface(study_params());
  std::size_t n = 0;
  ASSERT_EQ(texel_surface_size(s.get(), &n), TEXEL_OK);
  ASSERT_EQ(n, 19200u);
  texel_device_info info{};
  ASSERT_EQ(texel_surface_device(s.get(), &info), TEXEL_OK);
  EXPECT_EQ(info.samples, 19200);

  const std::vector<double> expected = cpp_map(study_spec());
  std::vector<double> m(n);
  ASSERT_EQ(texel_surface_render(s.get(), 0, m.data(), n), TEXEL_OK);
  EXPECT_EQ(m, expected);

  std::vector<std::uint16_t> u(n);
  ASSERT_EQ(texel_surface_render_u16(s.get(), 0, u.data(), n), TEXEL_OK);
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(u[i], texel::to_u16(expected[i])) << i;

  std::size_t needed = 0;
  ASSERT_EQ(texel_surface_render_native(s.get(), 0, n, nullptr, 0, &needed), TEXEL_OK);
  EXPECT_EQ(needed, 2 * n);
  std::vector<std::byte> native(needed);
  ASSERT_EQ(texel_surface_render_native(s.get(), 0, n, native.data(), native.size(), nullptr), TEXEL_OK);
  EXPECT_EQ(native, texel::prepare_surface(texel::make_document(texel::load_device("tpad"), study_spec()))
                        .render_native(texel::SampleFormat::u16le));
}

TEST(CApi, WindowsEqualTheWholeMap) {
  const Surf s = make_surface(study_params());
  const std::vector<double> whole = cpp_map(study_spec());
  for (const auto& [first, count] : {std::pair<std::int64_t, std::size_t>{0, 1}, {5, 1000}, {12345, 6855}, {19199, 1}}) {
    std::vector<double> w(count);
    ASSERT_EQ(texel_surface_render(s.get(), first, w.data(), count), TEXEL_OK);
    EXPECT_TRUE(std::equal(w.begin(), w.end(), whole.begin() + first)) << first;
    std::vector<std::uint16_t> u(count);
    ASSERT_EQ(texel_surface_render_u16(s.get(), first, u.data(), count), TEXEL_OK);
    for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(u[i], texel::to_u16(whole[first + i]));
    std::vector<std::uint8_t> b(2 * count);
    ASSERT_EQ(texel_surface_render_native(s.get(), first, count, b.data(), b.size(), nullptr), TEXEL_OK);
    for (std::size_t i = 0; i < count; ++i)
      ASSERT_EQ(b[2 * i] | (b[2 * i + 1] << 8), texel::to_u16(whole[first + i]));  // little-endian
  }
  // An empty window at the end is fine and needs no buffer.
  EXPECT_EQ(texel_surface_render(s.get(), 19200, nullptr, 0), TEXEL_OK);
  EXPECT_EQ(texel_surface_render_u16(s.get(), 0, nullptr, 0), TEXEL_OK);
}

TEST(CApi, CoarseSineAndOtherDevices) {
  texel_params p = study_params();
  p.coarse_strength = 0.7;
  p.fine_strength = 0.9;
  p.coarse_sine_period_mm = 5;
  p.coarse_sine_phase_deg = 30;
  p.quantization_db = 1;
  p.parameterization = TEXEL_PARAMETERIZATION_LOG;
  p.irregularity_db = 3;   // with 'log', the SD of 10·log10 f: >= 0
  p.central_pitch_db = 5;  // inside the band of the coarsest device ("generic": 6.3 dB)
  texel::TexelSpec spec = study_spec();
  spec.irregularity = texel::Decibels(3);
  spec.central_pitch = texel::Decibels(5);
  spec.coarse_strength = 0.7;
  spec.fine_strength = 0.9;
  spec.coarse = texel::SineProfile{texel::Millimetres(5), 30};
  spec.quantization_db = 1;
  spec.parameterization = texel::Parameterization::log;
  for (const char* device : {"tpad", "generic", "tpad-tablet"}) {
    const Surf s = make_surface(p, device);
    std::size_t n = 0;
    ASSERT_EQ(texel_surface_size(s.get(), &n), TEXEL_OK);
    std::vector<double> m(n);
    ASSERT_EQ(texel_surface_render(s.get(), 0, m.data(), n), TEXEL_OK);
    EXPECT_EQ(m, cpp_map(spec, device)) << device;
    texel_device_info info{};
    ASSERT_EQ(texel_surface_device(s.get(), &info), TEXEL_OK);
    std::size_t needed = 0;
    ASSERT_EQ(texel_surface_render_native(s.get(), 0, n, nullptr, 0, &needed), TEXEL_OK);
    EXPECT_EQ(needed, n * info.bytes_per_sample);
    std::vector<std::byte> bytes(needed);
    ASSERT_EQ(texel_surface_render_native(s.get(), 0, n, bytes.data(), bytes.size(), &needed), TEXEL_OK);
    const texel::DeviceProfile d = texel::load_device(device);
    EXPECT_EQ(bytes, texel::prepare_surface(texel::make_document(d, spec)).render_native(d.format)) << device;
  }
}

TEST(CApi, SurfaceErrors) {
  const Surf s = make_surface(study_params());
  std::vector<double> m(10);
  std::vector<std::uint16_t> u(10);
  std::vector<std::uint8_t> b(20);
  std::size_t n = 0;
  texel_device_info info{};
  EXPECT_FAILS(texel_surface_size(nullptr, &n), TEXEL_INVALID_ARGUMENT, "surface is NULL");
  EXPECT_FAILS(texel_surface_size(s.get(), nullptr), TEXEL_INVALID_ARGUMENT, "samples is NULL");
  EXPECT_FAILS(texel_surface_device(nullptr, &info), TEXEL_INVALID_ARGUMENT, "surface is NULL");
  EXPECT_FAILS(texel_surface_device(s.get(), nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");

  EXPECT_FAILS(texel_surface_render(nullptr, 0, m.data(), 10), TEXEL_INVALID_ARGUMENT, "surface is NULL");
  EXPECT_FAILS(texel_surface_render(s.get(), 0, nullptr, 10), TEXEL_INVALID_ARGUMENT, "out is NULL");
  EXPECT_FAILS(texel_surface_render(s.get(), -1, m.data(), 10), TEXEL_INVALID_ARGUMENT, "outside");
  EXPECT_FAILS(texel_surface_render(s.get(), 19195, m.data(), 10), TEXEL_INVALID_ARGUMENT, "19200");
  EXPECT_FAILS(texel_surface_render(s.get(), 19201, m.data(), 0), TEXEL_INVALID_ARGUMENT, "outside");
  EXPECT_FAILS(texel_surface_render(s.get(), INT64_MAX, m.data(), 10), TEXEL_INVALID_ARGUMENT, "outside");
  EXPECT_FAILS(texel_surface_render(s.get(), 1, m.data(), SIZE_MAX), TEXEL_INVALID_ARGUMENT, "outside");

  EXPECT_FAILS(texel_surface_render_u16(nullptr, 0, u.data(), 10), TEXEL_INVALID_ARGUMENT, "surface is NULL");
  EXPECT_FAILS(texel_surface_render_u16(s.get(), 0, nullptr, 10), TEXEL_INVALID_ARGUMENT, "out is NULL");
  EXPECT_FAILS(texel_surface_render_u16(s.get(), 19195, u.data(), 10), TEXEL_INVALID_ARGUMENT, "outside");

  std::size_t needed = 0;
  EXPECT_FAILS(texel_surface_render_native(nullptr, 0, 10, b.data(), b.size(), &needed), TEXEL_INVALID_ARGUMENT,
               "surface is NULL");
  EXPECT_FAILS(texel_surface_render_native(s.get(), 0, 10, nullptr, 0, nullptr), TEXEL_INVALID_ARGUMENT, "both NULL");
  EXPECT_FAILS(texel_surface_render_native(s.get(), 19195, 10, b.data(), b.size(), &needed), TEXEL_INVALID_ARGUMENT, "outside");
  std::fill(b.begin(), b.end(), 0xAB);
  EXPECT_FAILS(texel_surface_render_native(s.get(), 0, 10, b.data(), 19, &needed), TEXEL_BUFFER_TOO_SMALL, "20 needed");
  EXPECT_EQ(needed, 20u);
  EXPECT_EQ(b[0], 0xAB);  // nothing written
  EXPECT_EQ(texel_surface_render_native(s.get(), 0, 10, b.data(), 20, nullptr), TEXEL_OK);

  texel_surface* out = reinterpret_cast<texel_surface*>(&n);
  EXPECT_FAILS(texel_surface_create(nullptr, &out), TEXEL_INVALID_ARGUMENT, "doc is NULL");
  EXPECT_EQ(out, nullptr);
  const texel_params p = texel_params_default();
  EXPECT_FAILS(texel_surface_from_params("tpad", &p, nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
  EXPECT_FAILS(texel_surface_from_params("tpad", nullptr, &out), TEXEL_INVALID_ARGUMENT, "params is NULL");
  EXPECT_FAILS(texel_surface_from_params(nullptr, &p, &out), TEXEL_INVALID_ARGUMENT, "device is NULL");
}

TEST(CApi, OneSurfaceRendersFromManyThreads) {
  const Surf s = make_surface(study_params());
  const std::vector<double> whole = cpp_map(study_spec());
  std::vector<std::vector<double>> got(4, std::vector<double>(4800));
  std::vector<texel_status> status(4, TEXEL_INTERNAL);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < 4; ++t)
    threads.emplace_back(
        [&, t] { status[t] = texel_surface_render(s.get(), static_cast<std::int64_t>(t * 4800), got[t].data(), 4800); });
  for (auto& t : threads) t.join();
  for (std::size_t t = 0; t < 4; ++t) {
    EXPECT_EQ(status[t], TEXEL_OK);
    EXPECT_TRUE(std::equal(got[t].begin(), got[t].end(), whole.begin() + static_cast<std::ptrdiff_t>(t * 4800)));
  }
}

TEST(CApi, DestroyNullIsANoOp) {
  texel_document_destroy(nullptr);
  texel_surface_destroy(nullptr);
  texel_encode_result_destroy(nullptr);
  texel_player_destroy(nullptr);
  texel_spectrum_destroy(nullptr);
}

TEST(CApi, SurfaceOutlivesItsDocument) {
  const texel_params p = study_params();
  texel_document* d = nullptr;
  ASSERT_EQ(texel_document_from_params("tpad", &p, &d), TEXEL_OK);
  texel_surface* s = nullptr;
  ASSERT_EQ(texel_surface_create(d, &s), TEXEL_OK);
  texel_document_destroy(d);
  Surf surf(s);
  std::vector<double> m(19200);
  ASSERT_EQ(texel_surface_render(s, 0, m.data(), m.size()), TEXEL_OK);
  EXPECT_EQ(m, cpp_map(study_spec()));
}

// ------------------------------------------------------------------ codec

TEST(CApi, EncodeDecodeRoundTrip) {
  const Surf s = make_surface(study_params());
  std::vector<double> m(19200);
  ASSERT_EQ(texel_surface_render(s.get(), 0, m.data(), m.size()), TEXEL_OK);
  texel_device_info info{};
  ASSERT_EQ(texel_surface_device(s.get(), &info), TEXEL_OK);

  texel_encode_result* raw = nullptr;
  ASSERT_EQ(texel_encode(m.data(), m.size(), info.spacing_mm, &raw), TEXEL_OK) << texel_last_error();
  Enc enc(raw);

  // The same as the library's encoder with its defaults.
  texel::codec::Signal sig{m, texel::Millimetres(info.spacing_mm), "test"};
  const texel::codec::EncodeResult expected = texel::codec::encode(sig, texel::codec::EncoderConfig{});

  std::size_t needed = 0;
  ASSERT_EQ(texel_encode_result_bytes(raw, nullptr, 0, &needed), TEXEL_OK);
  ASSERT_EQ(needed, expected.bytes.size());
  std::vector<std::uint8_t> bytes(needed);
  EXPECT_FAILS(texel_encode_result_bytes(raw, bytes.data(), needed - 1, &needed), TEXEL_BUFFER_TOO_SMALL, "needed");
  ASSERT_EQ(texel_encode_result_bytes(raw, bytes.data(), bytes.size(), nullptr), TEXEL_OK);
  EXPECT_EQ(0, std::memcmp(bytes.data(), expected.bytes.data(), bytes.size()));

  texel_params p{};
  int has_profile = -1;
  ASSERT_EQ(texel_encode_result_params(raw, &p, &has_profile), TEXEL_OK);
  EXPECT_EQ(p.central_pitch_db, expected.spec.central_pitch.value());
  EXPECT_EQ(p.irregularity_db, expected.spec.irregularity.value());
  EXPECT_EQ(p.texel_length_mm, expected.spec.texel_length.value());
  EXPECT_EQ(p.seed, expected.spec.seed);
  EXPECT_EQ(has_profile, 0);  // a fine-only texture
  EXPECT_NEAR(p.central_pitch_db, 10.0, 0.5);
  ASSERT_EQ(texel_encode_result_params(raw, &p, nullptr), TEXEL_OK);
  double jnd = -1;
  ASSERT_EQ(texel_encode_result_distance(raw, &jnd), TEXEL_OK);
  EXPECT_EQ(jnd, expected.model_distance);

  // Decode on tpad: the decoder's document, rendered, byte for byte.
  texel_document* dd = nullptr;
  ASSERT_EQ(texel_decode(bytes.data(), bytes.size(), "tpad", &dd), TEXEL_OK) << texel_last_error();
  Doc decoded(dd);
  texel_surface* ds = nullptr;
  ASSERT_EQ(texel_surface_create(dd, &ds), TEXEL_OK);
  Surf dsurf(ds);
  std::vector<double> dm(19200);
  ASSERT_EQ(texel_surface_render(ds, 0, dm.data(), dm.size()), TEXEL_OK);
  const auto want =
      texel::prepare_surface(texel::codec::decode_document(texel::codec::parse_bitstream(std::as_bytes(std::span(bytes))),
                                                           texel::load_device("tpad")))
          .render();
  EXPECT_EQ(dm, want);

  // Errors.
  texel_encode_result* r = nullptr;
  EXPECT_FAILS(texel_encode(nullptr, 100, 0.005, &r), TEXEL_INVALID_ARGUMENT, "amplitudes is NULL");
  EXPECT_FAILS(texel_encode(m.data(), m.size(), nan_v, &r), TEXEL_INVALID_ARGUMENT, "spacing_mm");
  EXPECT_FAILS(texel_encode(m.data(), m.size(), -1, &r), TEXEL_INVALID_ARGUMENT, "spacing");
  EXPECT_FAILS(texel_encode(m.data(), 10, info.spacing_mm, &r), TEXEL_INVALID_ARGUMENT, "samples");
  EXPECT_FAILS(texel_encode(nullptr, 0, info.spacing_mm, &r), TEXEL_INVALID_ARGUMENT, "samples");
  EXPECT_FAILS(texel_encode(m.data(), m.size(), info.spacing_mm, nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
  std::vector<double> with_nan(m);
  with_nan[100] = nan_v;
  EXPECT_EQ(texel_encode(with_nan.data(), with_nan.size(), info.spacing_mm, &r), TEXEL_INVALID_ARGUMENT);
  EXPECT_EQ(r, nullptr);
  EXPECT_FAILS(texel_encode_result_bytes(nullptr, bytes.data(), bytes.size(), &needed), TEXEL_INVALID_ARGUMENT, "result is NULL");
  EXPECT_FAILS(texel_encode_result_bytes(raw, nullptr, 0, nullptr), TEXEL_INVALID_ARGUMENT, "both NULL");
  EXPECT_FAILS(texel_encode_result_params(nullptr, &p, nullptr), TEXEL_INVALID_ARGUMENT, "result is NULL");
  EXPECT_FAILS(texel_encode_result_params(raw, nullptr, nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
  EXPECT_FAILS(texel_encode_result_distance(nullptr, &jnd), TEXEL_INVALID_ARGUMENT, "result is NULL");
  EXPECT_FAILS(texel_encode_result_distance(raw, nullptr), TEXEL_INVALID_ARGUMENT, "jnd is NULL");
}

TEST(CApi, EncodeOptionsAndFiles) {
  const texel_encode_options d = texel_encode_options_default();
  const texel::codec::EncoderConfig c;
  EXPECT_EQ(d.boundary_mm, c.boundary.value());
  EXPECT_EQ(d.texel_length_mm, c.texel_length.value());
  EXPECT_EQ(d.parameterization, TEXEL_PARAMETERIZATION_MOMENTS);
  EXPECT_EQ(d.seed, c.seed);
  EXPECT_EQ(d.coarse_bits, c.coarse_bits);
  EXPECT_EQ(d.max_bytes, 0u);
  EXPECT_EQ(d.recover_texel, 1);
  EXPECT_EQ(d.swipe_speed_mm_s, c.model.swipe_speed.value());

  const Surf s = make_surface(study_params());
  std::vector<double> m(19200);
  ASSERT_EQ(texel_surface_render(s.get(), 0, m.data(), m.size()), TEXEL_OK);

  // Options reach the encoder: a seed and the log parameterization, as the library's encode with the same config.
  texel_encode_options o = d;
  o.seed = 99;
  o.parameterization = TEXEL_PARAMETERIZATION_LOG;
  o.recover_texel = 0;
  texel_encode_result* raw = nullptr;
  ASSERT_EQ(texel_encode_with(m.data(), m.size(), 0.005, &o, &raw), TEXEL_OK) << texel_last_error();
  Enc enc(raw);
  texel::codec::EncoderConfig cfg;
  cfg.seed = 99;
  cfg.parameterization = texel::Parameterization::log;
  cfg.recover_texel = false;
  const auto want = texel::codec::encode(texel::codec::Signal{m, texel::Millimetres(0.005), "t"}, cfg);
  std::vector<std::uint8_t> bytes(want.bytes.size());
  std::size_t needed = 0;
  ASSERT_EQ(texel_encode_result_bytes(raw, bytes.data(), bytes.size(), &needed), TEXEL_OK);
  EXPECT_EQ(0, std::memcmp(bytes.data(), want.bytes.data(), bytes.size()));
  texel_params p{};
  ASSERT_EQ(texel_encode_result_params(raw, &p, nullptr), TEXEL_OK);
  EXPECT_EQ(p.seed, 99u);
  EXPECT_EQ(p.parameterization, TEXEL_PARAMETERIZATION_LOG);

  // NULL options = the defaults = texel_encode.
  texel_encode_result* r1 = nullptr;
  texel_encode_result* r2 = nullptr;
  ASSERT_EQ(texel_encode_with(m.data(), m.size(), 0.005, nullptr, &r1), TEXEL_OK);
  ASSERT_EQ(texel_encode(m.data(), m.size(), 0.005, &r2), TEXEL_OK);
  Enc e1(r1), e2(r2);
  double j1 = 0, j2 = 1;
  ASSERT_EQ(texel_encode_result_distance(r1, &j1), TEXEL_OK);
  ASSERT_EQ(texel_encode_result_distance(r2, &j2), TEXEL_OK);
  EXPECT_EQ(j1, j2);

  // Bad options name the C field (the encoder's own field names).
  texel_encode_result* r = nullptr;
  auto bad = [&](auto mutate, const char* what) {
    texel_encode_options x = d;
    mutate(x);
    EXPECT_FAILS(texel_encode_with(m.data(), m.size(), 0.005, &x, &r), TEXEL_INVALID_ARGUMENT, what);
    EXPECT_EQ(r, nullptr);
  };
  bad([](texel_encode_options& x) { x.boundary_mm = 0; }, "boundary");
  bad([](texel_encode_options& x) { x.boundary_mm = nan_v; }, "boundary_mm");
  bad([](texel_encode_options& x) { x.texel_length_mm = 100; }, "texel_length");
  bad([](texel_encode_options& x) { x.coarse_bits = 17; }, "coarse_bits");
  bad([](texel_encode_options& x) { x.swipe_speed_mm_s = -1; }, "swipe_speed");
  bad([](texel_encode_options& x) { x.recover_texel = 2; }, "recover_texel");
  bad([](texel_encode_options& x) { std::memset(&x.parameterization, 7, 1); }, "parameterization");

  // A file through the one signal loader: the .bin of this map on tpad
  // encodes as the map itself does.
  TempDir dir("capi");
  const std::string bin = dir.at("map.bin");
  std::vector<std::uint16_t> u16(m.size());
  ASSERT_EQ(texel_surface_render_u16(s.get(), 0, u16.data(), u16.size()), TEXEL_OK);
  {
    std::FILE* f = std::fopen(bin.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(u16.data(), 2, u16.size(), f), u16.size());
    std::fclose(f);
  }
  texel_encode_result* rf = nullptr;
  ASSERT_EQ(texel_encode_file(bin.c_str(), "tpad", 0, nullptr, &rf), TEXEL_OK) << texel_last_error();
  Enc ef(rf);
  const auto sig = texel::codec::load_signal(bin, [] {
    texel::SignalOptions lo;
    lo.device = texel::load_device("tpad");
    return lo;
  }());
  const auto want_file = texel::codec::encode(texel::codec::encoder_signal(sig), texel::codec::EncoderConfig{});
  ASSERT_EQ(texel_encode_result_bytes(rf, nullptr, 0, &needed), TEXEL_OK);
  std::vector<std::uint8_t> fb(needed);
  ASSERT_EQ(texel_encode_result_bytes(rf, fb.data(), fb.size(), nullptr), TEXEL_OK);
  ASSERT_EQ(fb.size(), want_file.bytes.size());
  EXPECT_EQ(0, std::memcmp(fb.data(), want_file.bytes.data(), fb.size()));

  EXPECT_FAILS(texel_encode_file(bin.c_str(), nullptr, 0, nullptr, &r), TEXEL_INVALID_ARGUMENT, "device");
  EXPECT_FAILS(texel_encode_file(nullptr, "tpad", 0, nullptr, &r), TEXEL_INVALID_ARGUMENT, "path is NULL");
  EXPECT_FAILS(texel_encode_file(bin.c_str(), "tpad", -5, nullptr, &r), TEXEL_INVALID_ARGUMENT, "swipe_speed_mm_s");
  EXPECT_FAILS(texel_encode_file(bin.c_str(), "tpad", nan_v, nullptr, &r), TEXEL_INVALID_ARGUMENT, "swipe_speed_mm_s");
  EXPECT_FAILS(texel_encode_file(bin.c_str(), "tpad", 0, nullptr, nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
  EXPECT_EQ(texel_encode_file(dir.at("missing.bin").c_str(), "tpad", 0, nullptr, &r), TEXEL_IO_ERROR);
  EXPECT_EQ(r, nullptr);
}

TEST(CApi, DecodeErrors) {
  const texel::codec::Bitstream b;
  const std::vector<std::byte> encoded = texel::codec::write_bitstream(b);
  std::vector<std::uint8_t> good(encoded.size());
  std::memcpy(good.data(), encoded.data(), encoded.size());
  texel_document* d = nullptr;
  ASSERT_EQ(texel_decode(good.data(), good.size(), "tpad", &d), TEXEL_OK) << texel_last_error();
  texel_document_destroy(d);

  std::vector<std::uint8_t> bad = good;
  bad.back() ^= 0xFF;  // CRC
  d = reinterpret_cast<texel_document*>(&bad);
  EXPECT_EQ(texel_decode(bad.data(), bad.size(), "tpad", &d), TEXEL_FORMAT_ERROR);
  EXPECT_STRNE(texel_last_error(), "");
  EXPECT_EQ(d, nullptr);
  EXPECT_EQ(texel_decode(good.data(), 3, "tpad", &d), TEXEL_FORMAT_ERROR);  // truncated
  EXPECT_EQ(texel_decode(good.data(), 0, "tpad", &d), TEXEL_FORMAT_ERROR);
  EXPECT_FAILS(texel_decode(nullptr, 14, "tpad", &d), TEXEL_INVALID_ARGUMENT, "bytes is NULL");
  EXPECT_FAILS(texel_decode(good.data(), good.size(), nullptr, &d), TEXEL_INVALID_ARGUMENT, "device is NULL");
  EXPECT_FAILS(texel_decode(good.data(), good.size(), "nope", &d), TEXEL_INVALID_ARGUMENT, "nope");
  EXPECT_FAILS(texel_decode(good.data(), good.size(), "tpad", nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
}

// ----------------------------------------------------------------- player

TEST(CApi, PlayerConfigDefaults) {
  const texel_player_config c = texel_player_config_default();
  const texel::PlayerConfig l;
  EXPECT_EQ(c.rate_hz, l.rate_hz);
  EXPECT_EQ(c.mode, TEXEL_OUTPUT_AMPLITUDE);
  EXPECT_EQ(c.gain, l.gain);
  EXPECT_EQ(c.carrier_hz, l.carrier_hz);
  EXPECT_EQ(c.prediction_s, l.prediction_s);
  EXPECT_EQ(c.response_handling, TEXEL_RESPONSE_LIMIT);
  EXPECT_EQ(c.response_limit_db, l.response_limit_db);
}

// The display's frequency response reaches the C player through the
// surface's device (texel.h, docs/format.md "Frequency response"): a tpad
// surface is limited where the tpad cannot reproduce (first order at 400 Hz,
// limited from 3.98 kHz), a generic (flat) one is not, and OFF plays flat.
namespace response {

// One sinusoid of `cpm` cycles/mm over the whole of `device`.
Surf sine_surface(const char* device, double cpm) {
  const std::string json = std::string(R"({"format": "texel-document", "version": 3, "device": ")") + device +
                           R"(", "regions": [{"name": "all", "start_mm": 0, "texture": {"kind": "reference",
                           "name": "2sin", "params": {"frequencies_cpm": [)" +
                           std::to_string(cpm) + "]}}}]}";
  texel_document* d = nullptr;
  EXPECT_EQ(texel_document_parse(json.data(), json.size(), &d), TEXEL_OK) << texel_last_error();
  const Doc doc(d);
  texel_surface* s = nullptr;
  EXPECT_EQ(texel_surface_create(d, &s), TEXEL_OK) << texel_last_error();
  return Surf(s);
}

// Plays `surfaces` in turn (0.15 s each, at most three: the finger stays on
// the 100 mm surface) under a finger swiping at 200 mm/s from 5 mm (50 cpm →
// 10 kHz, 1 cpm → 200 Hz) at 48 kHz, vibration output; returns the RMS of
// each one's last 0.1 s (after the crossfade).
std::vector<double> swipe_rms(texel_response_handling h, const std::vector<const texel_surface*>& surfaces) {
  texel_player_config c = texel_player_config_default();
  c.rate_hz = 48000;
  c.mode = TEXEL_OUTPUT_VIBRATION;
  c.response_handling = h;
  texel_player* raw = nullptr;
  EXPECT_EQ(texel_player_create(&c, &raw), TEXEL_OK) << texel_last_error();
  const Play player(raw);
  std::vector<double> rms;
  std::vector<float> out(64);
  double pushed = 0.0;
  for (const texel_surface* s : surfaces) {
    EXPECT_EQ(texel_player_set_surface(raw, s), TEXEL_OK) << texel_last_error();
    double sum = 0.0;
    std::size_t n = 0;
    for (int block = 0; block < 113; ++block) {  // 0.15 s
      const double now = static_cast<double>(texel_player_samples(raw)) / c.rate_hz;
      for (; pushed <= now + 0.01; pushed += 0.001) EXPECT_EQ(texel_player_push(raw, pushed, 5.0 + 200.0 * pushed, 1), TEXEL_OK);
      EXPECT_EQ(texel_player_process(raw, out.data(), out.size(), nullptr), TEXEL_OK);
      if (block < 38) continue;  // 0.05 s: touch-down / crossfade
      for (float v : out) sum += static_cast<double>(v) * v;
      n += out.size();
    }
    rms.push_back(std::sqrt(sum / static_cast<double>(n)));
  }
  return rms;
}

double db(double ratio) { return 20.0 * std::log10(ratio); }

}  // namespace response

TEST(CApi, PlayerRespectsTheSurfaceDeviceResponse) {
  using response::db;
  using response::swipe_rms;
  const Surf tpad_high = response::sine_surface("tpad", 50.0);
  const Surf tpad_low = response::sine_surface("tpad", 1.0);
  const Surf generic_high = response::sine_surface("generic", 50.0);
  const auto limit = swipe_rms(TEXEL_RESPONSE_LIMIT, {tpad_high.get(), tpad_low.get()});
  const auto off = swipe_rms(TEXEL_RESPONSE_OFF, {tpad_high.get(), tpad_low.get()});
  std::cout << "rms 10 kHz: limit " << limit[0] << ", off " << off[0] << "; 200 Hz: limit " << limit[1] << ", off " << off[1]
            << "\n";
  EXPECT_GT(off[0], 0.1);
  EXPECT_GT(off[1], 0.1);
  EXPECT_LT(db(limit[0] / off[0]), -12.0);       // the 2nd-order Butterworth at 3.98 kHz: −16 dB at 10 kHz
  EXPECT_NEAR(db(limit[1] / off[1]), 0.0, 0.5);  // pass band untouched
  // The response follows each surface's device in one player: flat generic,
  // then the tpad, then generic again.
  const auto mixed = swipe_rms(TEXEL_RESPONSE_LIMIT, {generic_high.get(), tpad_high.get(), generic_high.get()});
  std::cout << "rms 10 kHz: generic " << mixed[0] << ", tpad " << mixed[1] << ", generic " << mixed[2] << "\n";
  EXPECT_GT(mixed[0], 0.1);
  EXPECT_GT(mixed[2], 0.1);
  EXPECT_LT(db(mixed[1] / mixed[0]), -12.0);
  EXPECT_NEAR(db(mixed[2] / mixed[0]), 0.0, 0.5);
}

TEST(CApi, PlayerPlaysTheMapUnderAFinger) {
  const Surf s = make_surface(study_params());
  texel_player_config c = texel_player_config_default();
  c.rate_hz = 8333;
  texel_player* raw = nullptr;
  ASSERT_EQ(texel_player_create(&c, &raw), TEXEL_OK) << texel_last_error();
  Play player(raw);
  EXPECT_EQ(texel_player_samples(raw), 0u);

  // Silent before a map.
  std::vector<float> out(256, -1.0f);
  ASSERT_EQ(texel_player_process(raw, out.data(), out.size(), nullptr), TEXEL_OK);
  for (float v : out) EXPECT_EQ(v, 0.0f);

  ASSERT_EQ(texel_player_set_surface(raw, s.get()), TEXEL_OK) << texel_last_error();
  // A swipe at 100 mm/s from 10 mm, queued ahead of time.
  const double t0 = static_cast<double>(texel_player_samples(raw)) / c.rate_hz;
  for (int i = 0; i <= 200; ++i) {
    const double t = t0 + i * 0.001;
    ASSERT_EQ(texel_player_push(raw, t, 10.0 + 100.0 * (t - t0), 1), TEXEL_OK);
  }
  std::vector<float> pos(out.size());
  float peak = 0;
  for (int block = 0; block < 4; ++block) {
    ASSERT_EQ(texel_player_process(raw, out.data(), out.size(), pos.data()), TEXEL_OK);
    for (float v : out) {
      EXPECT_GE(v, 0.0f);
      EXPECT_LE(v, 1.0f);
      peak = std::max(peak, v);
    }
  }
  EXPECT_GT(peak, 0.5f);
  EXPECT_GT(pos.back(), 10.0f);
  EXPECT_EQ(texel_player_samples(raw), 5u * out.size());
  ASSERT_EQ(texel_player_set_gain(raw, 0.5), TEXEL_OK);

  // A new map: the old one is retired by process and freed by collect.
  ASSERT_EQ(texel_player_set_surface(raw, s.get()), TEXEL_OK);
  for (int block = 0; block < 8; ++block) ASSERT_EQ(texel_player_process(raw, out.data(), out.size(), nullptr), TEXEL_OK);
  std::size_t freed = 99;
  ASSERT_EQ(texel_player_collect(raw, &freed), TEXEL_OK);
  EXPECT_EQ(freed, 1u);
  ASSERT_EQ(texel_player_collect(raw, nullptr), TEXEL_OK);
}

TEST(CApi, PlayerSurvivesTheSurface) {
  texel_surface* s = nullptr;
  const texel_params p = study_params();
  ASSERT_EQ(texel_surface_from_params("tpad", &p, &s), TEXEL_OK);
  texel_player_config c = texel_player_config_default();
  c.mode = TEXEL_OUTPUT_VIBRATION;
  texel_player* raw = nullptr;
  ASSERT_EQ(texel_player_create(&c, &raw), TEXEL_OK);
  Play player(raw);
  ASSERT_EQ(texel_player_set_surface(raw, s), TEXEL_OK);
  texel_surface_destroy(s);
  for (int i = 0; i < 100; ++i) ASSERT_EQ(texel_player_push(raw, i * 0.001, 20.0 + i * 0.1, 1), TEXEL_OK);
  std::vector<float> out(4800);
  ASSERT_EQ(texel_player_process(raw, out.data(), out.size(), nullptr), TEXEL_OK);
  for (float v : out) {
    EXPECT_GE(v, -1.0f);
    EXPECT_LE(v, 1.0f);
  }
}

TEST(CApi, PlayerErrors) {
  texel_player_config c = texel_player_config_default();
  texel_player* p = nullptr;
  EXPECT_FAILS(texel_player_create(nullptr, &p), TEXEL_INVALID_ARGUMENT, "config is NULL");
  EXPECT_FAILS(texel_player_create(&c, nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
  for (int bad_mode : {-1, 3, 1000}) {
    c = texel_player_config_default();
    c.mode = static_cast<texel_output_mode>(bad_mode);
    EXPECT_FAILS(texel_player_create(&c, &p), TEXEL_INVALID_ARGUMENT, "mode");
    EXPECT_EQ(p, nullptr);
  }
  struct Case {
    void (*mutate)(texel_player_config&);
    const char* field;
  };
  const Case cases[] = {
      {[](texel_player_config& x) { x.rate_hz = nan_v; }, "rate_hz"},
      {[](texel_player_config& x) { x.rate_hz = 10; }, "rate_hz"},
      {[](texel_player_config& x) { x.gain = 2; }, "gain"},
      {[](texel_player_config& x) { x.gain = nan_v; }, "gain"},
      {[](texel_player_config& x) { x.carrier_hz = -1; }, "carrier_hz"},
      {[](texel_player_config& x) { x.prediction_s = 1; }, "prediction_s"},
      {[](texel_player_config& x) { x.prediction_s = nan_v; }, "prediction_s"},
      {[](texel_player_config& x) { x.response_handling = static_cast<texel_response_handling>(2); }, "response_handling"},
      {[](texel_player_config& x) { x.response_handling = static_cast<texel_response_handling>(-1); }, "response_handling"},
      {[](texel_player_config& x) { x.response_limit_db = 1; }, "response_limit_db"},
      {[](texel_player_config& x) { x.response_limit_db = nan_v; }, "response_limit_db"},
  };
  for (const Case& k : cases) {
    c = texel_player_config_default();
    k.mutate(c);
    EXPECT_FAILS(texel_player_create(&c, &p), TEXEL_INVALID_ARGUMENT, k.field);
    EXPECT_EQ(p, nullptr);
  }

  c = texel_player_config_default();
  ASSERT_EQ(texel_player_create(&c, &p), TEXEL_OK);
  Play player(p);
  const Surf s = make_surface(study_params());
  EXPECT_FAILS(texel_player_set_surface(nullptr, s.get()), TEXEL_INVALID_ARGUMENT, "player is NULL");
  EXPECT_FAILS(texel_player_set_surface(p, nullptr), TEXEL_INVALID_ARGUMENT, "surface is NULL");
  EXPECT_FAILS(texel_player_push(nullptr, 0, 0, 1), TEXEL_INVALID_ARGUMENT, "player is NULL");
  EXPECT_FAILS(texel_player_push(p, nan_v, 0, 1), TEXEL_INVALID_ARGUMENT, "t_s");
  EXPECT_FAILS(texel_player_push(p, 0, INFINITY, 1), TEXEL_INVALID_ARGUMENT, "x_mm");
  EXPECT_FAILS(texel_player_set_gain(nullptr, 1), TEXEL_INVALID_ARGUMENT, "player is NULL");
  EXPECT_FAILS(texel_player_set_gain(p, nan_v), TEXEL_INVALID_ARGUMENT, "gain");
  EXPECT_EQ(texel_player_set_gain(p, 7), TEXEL_OK);  // clamped, as real-time parameters are
  EXPECT_FAILS(texel_player_collect(nullptr, nullptr), TEXEL_INVALID_ARGUMENT, "player is NULL");
  float out[4];
  EXPECT_EQ(texel_player_process(nullptr, out, 4, nullptr), TEXEL_INVALID_ARGUMENT);
  EXPECT_EQ(texel_player_process(p, nullptr, 4, nullptr), TEXEL_INVALID_ARGUMENT);
  EXPECT_EQ(texel_player_process(p, nullptr, 0, nullptr), TEXEL_OK);
  EXPECT_EQ(texel_player_samples(nullptr), 0u);

  // A full event queue is reported, not dropped silently.
  texel_status st = TEXEL_OK;
  int pushed = 0;
  for (; pushed < 10000 && st == TEXEL_OK; ++pushed) st = texel_player_push(p, pushed * 1e-4, 1.0, 1);
  EXPECT_EQ(st, TEXEL_BUFFER_TOO_SMALL);
  EXPECT_NE(std::string(texel_last_error()).find("queue is full"), std::string::npos);
  EXPECT_LE(pushed, 4097);
  float big[512];
  ASSERT_EQ(texel_player_process(p, big, 512, nullptr), TEXEL_OK);
  EXPECT_EQ(texel_player_push(p, 1.0, 1.0, 1), TEXEL_OK);
}

// --------------------------------------------------------------- spectrum

struct SpecDel {
  void operator()(texel_spectrum* s) const { texel_spectrum_destroy(s); }
};
using Spec = std::unique_ptr<texel_spectrum, SpecDel>;

std::vector<double> series_of(const texel_spectrum* s, texel_spectrum_series which) {
  std::size_t n = 0;
  EXPECT_EQ(texel_spectrum_get_series(s, which, nullptr, 0, &n), TEXEL_OK) << texel_last_error();
  std::vector<double> v(n);
  EXPECT_EQ(texel_spectrum_get_series(s, which, v.data(), v.size(), nullptr), TEXEL_OK) << texel_last_error();
  return v;
}

TEST(CApi, SpectrumEqualsTheLibrarys) {
  const std::vector<double> map = cpp_map(study_spec());
  const double spacing = texel::load_device("tpad").spacing.value();
  texel_spectrum_options o = texel_spectrum_options_default();
  EXPECT_EQ(o.window, TEXEL_WINDOW_BLACKMAN_HARRIS);
  EXPECT_EQ(o.zero_pad, 4u);
  EXPECT_EQ(o.max_peaks, 32u);
  o.window = TEXEL_WINDOW_HANN;
  o.threshold_db = -30;
  texel_spectrum* raw = nullptr;
  ASSERT_EQ(texel_spectrum_analyse(map.data(), map.size(), spacing, &o, &raw), TEXEL_OK) << texel_last_error();
  const Spec s(raw);

  texel::AnalysisOptions a;
  a.spectrum.window = texel::Window::hann;
  a.peaks.threshold = texel::DecibelsLevel{-30.0};
  const texel::SpectralReport r = texel::analyse_spectrum(map, texel::Millimetres(spacing), a);
  texel_spectrum_summary m{};
  ASSERT_EQ(texel_spectrum_get_summary(s.get(), &m), TEXEL_OK);
  EXPECT_EQ(m.samples, map.size());
  EXPECT_EQ(m.nfft, r.spectrum.nfft);
  EXPECT_EQ(m.centroid_cpm, r.summary.centroid.value());
  EXPECT_EQ(m.log_centroid_db, r.summary.log_centroid.value());
  EXPECT_EQ(m.rms_amplitude, r.rms);
  EXPECT_EQ(m.welch_segments, r.psd.segments);
  EXPECT_EQ(series_of(s.get(), TEXEL_SERIES_MAGNITUDE), r.spectrum.magnitude);
  EXPECT_EQ(series_of(s.get(), TEXEL_SERIES_PSD), r.psd.density);
  const std::vector<double> peaks = series_of(s.get(), TEXEL_SERIES_PEAK_FREQUENCY_CPM);
  ASSERT_EQ(peaks.size(), r.peaks.size());
  for (std::size_t k = 0; k < peaks.size(); ++k) EXPECT_EQ(peaks[k], r.peaks[k].frequency.value());
  EXPECT_EQ(series_of(s.get(), TEXEL_SERIES_BAND_FRACTION).size(), r.bands.size());

  // Defaults (NULL options) are texel spectrum's.
  ASSERT_EQ(texel_spectrum_analyse(map.data(), map.size(), spacing, nullptr, &raw), TEXEL_OK);
  const Spec d(raw);
  EXPECT_EQ(series_of(d.get(), TEXEL_SERIES_MAGNITUDE),
            texel::analyse_spectrum(map, texel::Millimetres(spacing)).spectrum.magnitude);
}

TEST(CApi, SpectrumErrors) {
  const std::vector<double> map(64, 0.5);
  texel_spectrum* s = reinterpret_cast<texel_spectrum*>(1);
  EXPECT_FAILS(texel_spectrum_analyse(map.data(), 8, 0.01, nullptr, &s), TEXEL_INVALID_ARGUMENT, "at least 16");
  EXPECT_EQ(s, nullptr);
  EXPECT_FAILS(texel_spectrum_analyse(nullptr, 64, 0.01, nullptr, &s), TEXEL_INVALID_ARGUMENT, "amplitudes is NULL");
  EXPECT_FAILS(texel_spectrum_analyse(map.data(), 64, nan_v, nullptr, &s), TEXEL_INVALID_ARGUMENT, "spacing_mm");
  EXPECT_FAILS(texel_spectrum_analyse(map.data(), 64, 0.01, nullptr, nullptr), TEXEL_INVALID_ARGUMENT, "out is NULL");
  texel_spectrum_options o = texel_spectrum_options_default();
  o.zero_pad = 0;
  EXPECT_FAILS(texel_spectrum_analyse(map.data(), 64, 0.01, &o, &s), TEXEL_INVALID_ARGUMENT, "zero_pad is 0");
  o = texel_spectrum_options_default();
  o.threshold_db = 3;
  EXPECT_FAILS(texel_spectrum_analyse(map.data(), 64, 0.01, &o, &s), TEXEL_INVALID_ARGUMENT, "threshold_db");
  o = texel_spectrum_options_default();
  o.welch_overlap = 0.99;
  EXPECT_FAILS(texel_spectrum_analyse(map.data(), 64, 0.01, &o, &s), TEXEL_INVALID_ARGUMENT, "welch_overlap");
  o = texel_spectrum_options_default();
  const int bad = 9;
  std::memcpy(&o.window, &bad, sizeof bad);
  EXPECT_FAILS(texel_spectrum_analyse(map.data(), 64, 0.01, &o, &s), TEXEL_INVALID_ARGUMENT, "window is 9");

  std::vector<double> ramp(256);
  for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = std::sin(0.3 * static_cast<double>(i)) * 0.5 + 0.5;
  ASSERT_EQ(texel_spectrum_analyse(ramp.data(), ramp.size(), 0.01, nullptr, &s), TEXEL_OK) << texel_last_error();
  const Spec sp(s);
  std::size_t n = 0;
  ASSERT_EQ(texel_spectrum_get_series(sp.get(), TEXEL_SERIES_FREQUENCY_CPM, nullptr, 0, &n), TEXEL_OK);
  ASSERT_GT(n, 1u);
  std::vector<double> few(n - 1);
  std::size_t needed = 0;
  EXPECT_FAILS(texel_spectrum_get_series(sp.get(), TEXEL_SERIES_FREQUENCY_CPM, few.data(), few.size(), &needed),
               TEXEL_BUFFER_TOO_SMALL, "needed");
  EXPECT_EQ(needed, n);  // values, not bytes
  EXPECT_FAILS(texel_spectrum_get_series(sp.get(), TEXEL_SERIES_FREQUENCY_CPM, nullptr, 0, nullptr), TEXEL_INVALID_ARGUMENT,
               "both NULL");
  texel_spectrum_series series;
  const int worse = 11;
  std::memcpy(&series, &worse, sizeof worse);
  EXPECT_FAILS(texel_spectrum_get_series(sp.get(), series, nullptr, 0, &n), TEXEL_INVALID_ARGUMENT, "series is 11");
  EXPECT_FAILS(texel_spectrum_get_summary(nullptr, nullptr), TEXEL_INVALID_ARGUMENT, "spectrum is NULL");
}

// Encode flags (docs/encoder.md, "Honest results"): a constant input is
// flagged, or refused with refuse_no_texture; version 1 stays selectable.
TEST(CApiEncode, FlagsNameTheModelAndAnInputWithoutTexture) {
  std::vector<double> flat(19200, 0.5);
  texel_encode_result* raw = nullptr;
  ASSERT_EQ(texel_encode(flat.data(), flat.size(), 0.0053, &raw), TEXEL_OK) << texel_last_error();
  texel_encode_flags f{};
  ASSERT_EQ(texel_encode_result_flags(raw, &f), TEXEL_OK);
  EXPECT_EQ(f.model_version, 2);
  EXPECT_EQ(f.no_texture, 1);
  EXPECT_EQ(f.irregularity_identifiable, 0);
  EXPECT_EQ(f.central_pitch_at_bound, 0);
  EXPECT_FAILS(texel_encode_result_flags(raw, nullptr), TEXEL_INVALID_ARGUMENT, "out");
  texel_encode_result_destroy(raw);
  texel_encode_options o = texel_encode_options_default();
  EXPECT_EQ(o.model_version, 2);
  EXPECT_EQ(o.refuse_no_texture, 0);
  o.refuse_no_texture = 1;
  EXPECT_FAILS(texel_encode_with(flat.data(), flat.size(), 0.0053, &o, &raw), TEXEL_INVALID_ARGUMENT, "no texture");
  o.refuse_no_texture = 0;
  o.model_version = 1;
  std::vector<double> wave(19200);
  for (std::size_t i = 0; i < wave.size(); ++i) wave[i] = 0.5 + 0.4 * std::sin(0.3 * static_cast<double>(i));
  ASSERT_EQ(texel_encode_with(wave.data(), wave.size(), 0.0053, &o, &raw), TEXEL_OK) << texel_last_error();
  ASSERT_EQ(texel_encode_result_flags(raw, &f), TEXEL_OK);
  EXPECT_EQ(f.model_version, 1);
  EXPECT_EQ(f.no_texture, 0);
  texel_encode_result_destroy(raw);
  o.model_version = 3;
  EXPECT_FAILS(texel_encode_with(wave.data(), wave.size(), 0.0053, &o, &raw), TEXEL_INVALID_ARGUMENT, "model_version");
}

}  // namespace

// Issue 39: the C structs' defaults are the library's description of each
// operation's options (visit_options, texel/option_spec.hpp) — the same
// description the CLI's help and Python's keyword defaults are made from
// (tests/python/test_front_door_defaults.py checks those and texel.h's
// "[default]" comments). A default typed by hand into a *_default() fails
// here. Every C field with a described counterpart is compared; enumerations
// by value (texel.h's enumerators equal the library's).
TEST(CApi, EveryDefaultIsTheLibrarysDescription) {
  const auto d = [](const auto& defaults, std::string_view key) { return texel::option_default(defaults, key); };
  const auto n = [](auto v) { return static_cast<double>(v); };

  const texel::TexelSpec spec;
  const texel_params p = texel_params_default();
  EXPECT_EQ(n(p.central_pitch_db), d(spec, "central_pitch_db"));
  EXPECT_EQ(n(p.irregularity_db), d(spec, "irregularity_db"));
  EXPECT_EQ(n(p.texel_length_mm), d(spec, "texel_length_mm"));
  EXPECT_EQ(n(p.seed), d(spec, "seed"));
  EXPECT_EQ(n(p.parameterization), d(spec, "parameterization"));
  EXPECT_EQ(n(p.quantization_db), d(spec, "quantization_db"));
  EXPECT_EQ(n(p.coarse_strength), d(spec, "coarse_strength"));
  EXPECT_EQ(n(p.fine_strength), d(spec, "fine_strength"));

  const texel::codec::EncoderConfig enc;
  const texel_encode_options e = texel_encode_options_default();
  EXPECT_EQ(n(e.boundary_mm), d(enc, "boundary_mm"));
  EXPECT_EQ(n(e.texel_length_mm), d(enc, "texel_length_mm"));
  EXPECT_EQ(n(e.parameterization), d(enc, "parameterization"));
  EXPECT_EQ(n(e.seed), d(enc, "seed"));
  EXPECT_EQ(n(e.coarse_bits), d(enc, "coarse_bits"));
  EXPECT_TRUE(std::isnan(d(enc, "max_bytes")) ? e.max_bytes == 0 : n(e.max_bytes) == d(enc, "max_bytes"));  // 0 = none
  EXPECT_EQ(n(e.model_version), d(enc, "model"));
  EXPECT_EQ(n(e.refuse_no_texture), d(enc, "no_texture"));  // flag (0) or refuse (1)
  EXPECT_EQ(n(e.target), d(enc, "target"));

  const texel::PlayerConfig player;
  const texel_player_config c = texel_player_config_default();
  EXPECT_EQ(n(c.rate_hz), d(player, "rate_hz"));
  EXPECT_EQ(n(c.mode), d(player, "output"));
  EXPECT_EQ(n(c.gain), d(player, "gain"));
  EXPECT_EQ(n(c.carrier_hz), d(player, "carrier_hz"));
  EXPECT_EQ(n(c.prediction_s), d(player, "prediction_s"));
  EXPECT_EQ(n(c.response_handling), d(player, "response"));
  EXPECT_EQ(n(c.response_limit_db), d(player, "response_limit_db"));

  const texel::Path2DConfig path;
  const texel_path2d_config q = texel_path2d_config_default();
  EXPECT_EQ(n(q.shape), d(path, "path"));
  EXPECT_EQ(n(q.speed_mm_s), d(path, "speed_mm_s"));
  EXPECT_EQ(n(q.angle_deg), d(path, "angle_deg"));
  EXPECT_EQ(n(q.start_x_mm), d(path, "start_x_mm"));
  EXPECT_EQ(n(q.start_y_mm), d(path, "start_y_mm"));
  EXPECT_EQ(n(q.radius_mm), d(path, "radius_mm"));
  EXPECT_EQ(n(q.leg_mm), d(path, "leg_mm"));
  EXPECT_EQ(n(q.zigzag_deg), d(path, "zigzag_deg"));
  EXPECT_EQ(n(q.duration_s), d(path, "duration_s"));
  EXPECT_EQ(n(q.rate_hz), d(path, "rate_hz"));
}
