// `texel encode` on 2-D inputs through the real binary: a map rendered by
// `texel render --surface 2d` encodes to a version-4 document that renders
// again; bad input exits 2 with one line and leaves no file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

#include "../support/cli_run.hpp"
#include "../support/temp_dir.hpp"
#include "texel/document.hpp"

using texel::test_support::run_cli;
using texel::test_support::TempDir;

namespace {

const std::string cli = TEXEL_CLI_PATH;

const char* kDocument = R"({"format": "texel-document", "version": 4, "description": "encode2d CLI test",
 "device": {"name": "grid-2d", "samples": 200, "spacing_mm": 0.05, "format": "f32le", "refresh_hz": 6250,
            "bitmap": {"width_px": 200, "height_px": 160, "pixel_pitch_mm": 0.05, "depth_bits": 16,
                       "polarity": "darker_more_friction"}},
 "surface2d": {"regions": [{"name": "a", "field": "spectral",
   "texture": {"kind": "texel", "central_pitch_db": 3, "irregularity_db": -5, "texel_length_mm": 0.5, "seed": 2,
               "coarse_strength": 0.8, "fine_strength": 0.6},
   "coarse2d": {"kind": "disc", "x_mm": 5, "y_mm": 4, "radius_mm": 2.5, "edge_mm": 0.5, "inside": 1, "outside": 0}}]}})";

std::size_t lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

TEST(Encode2DCli, RenderEncodeRenderAgain) {
  TempDir dir("encode2d-cli");
  const std::string doc = dir.write("in.texel.json", kDocument);
  ASSERT_EQ(run_cli(cli, "render " + doc + " --surface 2d -o " + dir.at("map.png")).status, 0);
  const auto r = run_cli(cli, "encode " + dir.at("map.png") + " --pitch 0.05 --directions 8 -o " + dir.at("out.texel.json"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("Central Pitch"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("anisotropy: isotropic"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("coarse image"), std::string::npos) << r.out;
  ASSERT_TRUE(std::filesystem::exists(dir.at("out.coarse.npy")));
  const texel::Document back = texel::load_document(dir.at("out.texel.json"));
  EXPECT_EQ(back.version, 4);
  ASSERT_TRUE(back.surface2d);
  EXPECT_EQ(back.device.bitmap->width, 200);
  EXPECT_EQ(back.device.bitmap->height, 160);
  EXPECT_EQ(run_cli(cli, "render " + dir.at("out.texel.json") + " --surface 2d -o " + dir.at("again.png")).status, 0);
  // --json: the library's serialisation with the input and output.
  const auto j = run_cli(cli, "encode " + dir.at("map.png") + " --pitch 0.05 --directions 4 --json", false);
  ASSERT_EQ(j.status, 0) << j.out;
  EXPECT_NE(j.out.find("\"method\": \"bitmap\""), std::string::npos) << j.out;
  EXPECT_NE(j.out.find("\"directions\": ["), std::string::npos) << j.out;
}

TEST(Encode2DCli, BadInputExitsTwoWithOneLineAndNoFile) {
  TempDir dir("encode2d-cli");
  const std::string doc = dir.write("in.texel.json", kDocument);
  ASSERT_EQ(run_cli(cli, "render " + doc + " --surface 2d -o " + dir.at("map.png")).status, 0);
  for (const std::string& args :
       {"encode " + dir.at("map.png") + " -o " + dir.at("out.texel.json"),
        "encode " + dir.at("map.png") + " --pitch 0.05 -o " + dir.at("out.texel"),
        "encode " + dir.at("map.png") + " --pitch 0.05 --device tpad -o " + dir.at("out.texel.json"),
        "encode " + dir.at("map.png") + " --pitch 0.05 --max-bytes 20 -o " + dir.at("out.texel.json")}) {
    const auto r = run_cli(cli, args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.out;
    EXPECT_EQ(lines(r.out), 1u) << r.out;
  }
  EXPECT_EQ(dir.listing(), (std::set<std::string>{"in.texel.json", "map.png"}));
  const auto r = run_cli(cli, "encode " + dir.at("map.png") + " -o " + dir.at("out.texel.json"));
  EXPECT_NE(r.out.find("--pitch"), std::string::npos) << r.out;
}
