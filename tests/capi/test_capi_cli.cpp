// The C ABI renders the same bytes as the `texel` command: a Texel texture
// (`texel render`), a reference (`texel reference`) and a decoded bitstream
// (`texel decode`), each compared with the file the command writes.
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../support/cli_run.hpp"
#include "../support/temp_dir.hpp"
#include "texel.h"

namespace {

using texel::test_support::run_cli;
using texel::test_support::TempDir;

std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The surface's whole map in device bytes, through the C ABI.
std::vector<std::uint8_t> native_map(const texel_surface* s) {
  std::size_t n = 0, needed = 0;
  EXPECT_EQ(texel_surface_size(s, &n), TEXEL_OK);
  EXPECT_EQ(texel_surface_render_native(s, 0, n, nullptr, 0, &needed), TEXEL_OK);
  std::vector<std::uint8_t> bytes(needed);
  EXPECT_EQ(texel_surface_render_native(s, 0, n, bytes.data(), bytes.size(), &needed), TEXEL_OK) << texel_last_error();
  return bytes;
}

std::vector<std::uint8_t> document_map(texel_document* d) {
  texel_surface* s = nullptr;
  EXPECT_EQ(texel_surface_create(d, &s), TEXEL_OK) << texel_last_error();
  auto bytes = native_map(s);
  texel_surface_destroy(s);
  texel_document_destroy(d);
  return bytes;
}

TEST(CApiCli, RenderEqualsTexelRender) {
  TempDir dir("capi-cli");
  const std::string bin = dir.at("a.bin");
  const auto r =
      run_cli(TEXEL_CLI, "render --central-pitch 10 --irregularity -5 --texel-length 0.25 --seed 7 --device tpad -o " + bin);
  ASSERT_EQ(r.status, 0) << r.out;
  const auto expected = read_bytes(bin);
  ASSERT_EQ(expected.size(), 2u * 19200u);

  texel_params p = texel_params_default();
  p.central_pitch_db = 10;
  p.irregularity_db = -5;
  p.texel_length_mm = 0.25;
  p.seed = 7;
  texel_surface* s = nullptr;
  ASSERT_EQ(texel_surface_from_params("tpad", &p, &s), TEXEL_OK) << texel_last_error();
  EXPECT_EQ(native_map(s), expected);
  // uint16 in host order is the same file on a little-endian host.
  std::vector<std::uint16_t> u(19200);
  ASSERT_EQ(texel_surface_render_u16(s, 0, u.data(), u.size()), TEXEL_OK);
  for (std::size_t i = 0; i < u.size(); ++i) ASSERT_EQ(u[i], expected[2 * i] | (expected[2 * i + 1] << 8)) << i;
  texel_surface_destroy(s);
}

TEST(CApiCli, CoarseAndLogEqualTexelRender) {
  TempDir dir("capi-cli");
  const std::string bin = dir.at("b.bin");
  const auto r = run_cli(TEXEL_CLI,
                         "render --central-pitch 6 --irregularity 2 --texel-length 0.5 --seed 42 --parameterization log "
                         "--quantization 2 --coarse-strength 0.6 --fine-strength 0.8 --coarse-sine 4 --coarse-phase 90 "
                         "--device tpad-tablet -o " +
                             bin);
  ASSERT_EQ(r.status, 0) << r.out;
  texel_params p = texel_params_default();
  p.central_pitch_db = 6;
  p.irregularity_db = 2;
  p.texel_length_mm = 0.5;
  p.seed = 42;
  p.parameterization = TEXEL_PARAMETERIZATION_LOG;
  p.quantization_db = 2;
  p.coarse_strength = 0.6;
  p.fine_strength = 0.8;
  p.coarse_sine_period_mm = 4;
  p.coarse_sine_phase_deg = 90;
  texel_surface* s = nullptr;
  ASSERT_EQ(texel_surface_from_params("tpad-tablet", &p, &s), TEXEL_OK) << texel_last_error();
  EXPECT_EQ(native_map(s), read_bytes(bin));
  texel_surface_destroy(s);
}

TEST(CApiCli, ReferenceEqualsTexelReference) {
  TempDir dir("capi-cli");
  const std::string bin = dir.at("pink.bin");
  const auto r = run_cli(TEXEL_CLI, "reference pink --seed 5 --device tpad -o " + bin);
  ASSERT_EQ(r.status, 0) << r.out;
  texel_document* d = nullptr;
  ASSERT_EQ(texel_document_from_reference("tpad", "pink", 5, &d), TEXEL_OK) << texel_last_error();
  EXPECT_EQ(document_map(d), read_bytes(bin));
}

TEST(CApiCli, DecodeEqualsTexelDecode) {
  TempDir dir("capi-cli");
  const std::string map = dir.at("in.bin"), stream = dir.at("in.texel"), out = dir.at("out.bin");
  ASSERT_EQ(run_cli(TEXEL_CLI, "render --central-pitch 12 --seed 3 -o " + map).status, 0);
  const auto e = run_cli(TEXEL_CLI, "encode " + map + " --device tpad -o " + stream);
  ASSERT_EQ(e.status, 0) << e.out;
  const auto d = run_cli(TEXEL_CLI, "decode " + stream + " --device generic -o " + out);
  ASSERT_EQ(d.status, 0) << d.out;
  const auto bytes = read_bytes(stream);
  texel_document* doc = nullptr;
  ASSERT_EQ(texel_decode(bytes.data(), bytes.size(), "generic", &doc), TEXEL_OK) << texel_last_error();
  EXPECT_EQ(document_map(doc), read_bytes(out));
}

TEST(CApiCli, EncodeEqualsTexelEncode) {
  TempDir dir("capi-cli");
  const std::string map = dir.at("in.bin"), stream = dir.at("in.texel");
  ASSERT_EQ(run_cli(TEXEL_CLI, "render --central-pitch 8 --irregularity -3 --seed 9 -o " + map).status, 0);
  const auto e = run_cli(TEXEL_CLI, "encode " + map + " --device tpad -o " + stream);
  ASSERT_EQ(e.status, 0) << e.out;
  texel_params p = texel_params_default();
  p.central_pitch_db = 8;
  p.irregularity_db = -3;
  p.seed = 9;
  texel_surface* s = nullptr;
  ASSERT_EQ(texel_surface_from_params("tpad", &p, &s), TEXEL_OK);
  std::vector<double> m(19200);
  ASSERT_EQ(texel_surface_render(s, 0, m.data(), m.size()), TEXEL_OK);
  texel_device_info info{};
  ASSERT_EQ(texel_surface_device(s, &info), TEXEL_OK);
  texel_surface_destroy(s);
  // The CLI reads the u16 file back; encode the same quantized amplitudes.
  for (double& a : m) a = static_cast<double>(static_cast<std::uint16_t>(a * 65535.0 + 0.5)) / 65535.0;
  texel_encode_result* r = nullptr;
  ASSERT_EQ(texel_encode(m.data(), m.size(), info.spacing_mm, &r), TEXEL_OK) << texel_last_error();
  std::size_t needed = 0;
  ASSERT_EQ(texel_encode_result_bytes(r, nullptr, 0, &needed), TEXEL_OK);
  std::vector<std::uint8_t> bytes(needed);
  ASSERT_EQ(texel_encode_result_bytes(r, bytes.data(), bytes.size(), nullptr), TEXEL_OK);
  texel_encode_result_destroy(r);
  EXPECT_EQ(bytes, read_bytes(stream));
}

}  // namespace
