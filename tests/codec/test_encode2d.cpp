// The 2-D encoder (docs/encoder.md "2-D inputs"): round trips through the
// library's 2-D renderer (spectral field and cells), anisotropy of a
// grating, PNG 8/16-bit and .npy inputs, a coarse disc found at its place,
// scan bundles, and clear errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "texel/bitmap_file.hpp"
#include "texel/document.hpp"
#include "texel/encode2d.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/signal.hpp"
#include "texel/surface2d.hpp"

using namespace texel;
using texel::test_support::message_of;
using texel::test_support::TempDir;

namespace {

constexpr int kSide = 256;
constexpr double kPitch = 0.05;
// Round-trip tolerances (docs/encoder.md "2-D inputs", measured errors beside them).
constexpr double kPitchTolerance = 0.5;         // narrow, spectral: measured within 0.25 dB
constexpr double kCellsPitchTolerance = 0.75;   // narrow, cells: measured within 0.34 dB
constexpr double kWidePitchTolerance = 1.0;     // P 0, I 5 dB: measured -0.23 dB
constexpr double kIrregularityTolerance = 2.5;  // P 0, I 5 dB: measured +1.71 dB
constexpr double kScansPitchTolerance = 1.0;

DeviceProfile grid_device(int w = kSide, int h = kSide, double pitch = kPitch, int depth = 16) {
  DeviceProfile d = load_device("tablet-2d");
  d.name = "test-2d";
  d.samples = w;
  d.spacing = Millimetres(pitch);
  d.bitmap = BitmapGeometry{w, h, Millimetres(pitch), depth, BitmapPolarity::darker_more_friction};
  return d;
}

Document texture_document(double p, double i, double l, Field2D field, Coarse2D coarse = ConstantProfile{}, double c = 0.0,
                          double f = 1.0, double orientation = 0.0) {
  Document doc;
  doc.device = grid_device();
  doc.device_inline = true;
  Region2DSpec r;
  r.texel.central_pitch = Decibels(p);
  r.texel.irregularity = Decibels(i);
  r.texel.texel_length = Millimetres(l);
  r.texel.seed = 5;
  r.texel.coarse_strength = c;
  r.texel.fine_strength = f;
  r.field = field;
  r.orientation_deg = orientation;
  r.coarse = coarse;
  doc.surface2d = Surface2DSpec{{r}};
  return doc;
}

Raster2D render(const Document& doc) {
  Raster2D r = render_raster(prepare_surface2d(doc));
  r.pitch = doc.device.bitmap->pitch;
  return r;
}

codec::Encode2DConfig quick_config() {
  codec::Encode2DConfig c;
  c.directions = 12;
  c.scan_samples = 8192;
  return c;
}

}  // namespace

TEST(Encode2D, Explore) {
  if (!std::getenv("TEXEL_ENCODE2D_EXPLORE")) GTEST_SKIP();
  for (Field2D field : {Field2D::spectral, Field2D::cells})
    for (double p : {0.0, 3.0})
      for (double i : {-10.0, -5.0, 0.0, 5.0}) {
        const double l = 0.5;
        const Raster2D map = render(texture_document(p, i, l, field));
        const std::clock_t t0 = std::clock();
        const codec::Encode2DResult r = codec::encode_surface2d(map, quick_config());
        const double s = static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
        std::printf(
            "%s P %5.1f I %5.1f L %.2f -> P %6.2f I %6.2f L %.3f%s field %s ident %d mean %.2f/%.2f spread %.2f/%.2f C %.3f F "
            "%.3f coarse %d res %.2f  %.2fs\n",
            std::string(to_string(field)).c_str(), p, i, l, r.spec.central_pitch.value(), r.spec.irregularity.value(),
            r.spec.texel_length.value(), r.texel_length_detected ? "*" : " ", std::string(to_string(r.field)).c_str(),
            r.irregularity_identifiable, r.mean_central_pitch_db, r.mean_irregularity_db, r.central_pitch_spread_db,
            r.irregularity_spread_db, r.spec.coarse_strength, r.spec.fine_strength, r.coarse, r.correction_residual_db, s);
      }
}

// --- round trips ---------------------------------------------------------------

namespace {

struct Case {
  double p, i, l;
  Field2D field;
};

codec::Encode2DResult round_trip(const Case& c, const codec::Encode2DConfig& cfg = quick_config()) {
  const codec::Encode2DResult r = codec::encode_surface2d(render(texture_document(c.p, c.i, c.l, c.field)), cfg);
  std::printf("%s P %.1f I %.1f L %.2f -> P %.2f I %.2f L %.3f (%s), identifiable %d, spread P %.2f I %.2f dB\n",
              std::string(to_string(c.field)).c_str(), c.p, c.i, c.l, r.spec.central_pitch.value(), r.spec.irregularity.value(),
              r.spec.texel_length.value(), r.texel_length_detected ? "lattice" : "setting", r.irregularity_identifiable,
              r.central_pitch_spread_db, r.irregularity_spread_db);
  return r;
}

}  // namespace

// A narrow texture on the spectral field: its Central Pitch comes back; its
// Irregularity is not identifiable (every narrower texture renders the same
// field, docs/algorithm.md §11.1) and is said so, with the bound.
TEST(Encode2D, SpectralFieldRoundTripNarrow) {
  const codec::Encode2DResult r = round_trip({3.0, -5.0, 0.5, Field2D::spectral});
  EXPECT_NEAR(r.spec.central_pitch.value(), 3.0, kPitchTolerance);
  EXPECT_FALSE(r.irregularity_identifiable);
  EXPECT_GT(r.irregularity_bound_db, r.spec.irregularity.value());
  EXPECT_EQ(r.field, Field2D::spectral);
  EXPECT_FALSE(r.texel_length_detected);
  EXPECT_FALSE(r.anisotropic);
  EXPECT_LT(r.central_pitch_spread_db, 1.0);
  EXPECT_FALSE(r.coarse);
  EXPECT_NEAR(r.spec.fine_strength, 1.0, 0.05);
  EXPECT_NEAR(r.spec.coarse_strength, 0.0, 0.05);
  ASSERT_TRUE(r.document.surface2d);
  EXPECT_EQ(required_version(r.document), 4);
}

// A texture wider than the cosine law's spread: Central Pitch and Irregularity both come back.
TEST(Encode2D, SpectralFieldRoundTripWide) {
  const codec::Encode2DResult r = round_trip({0.0, 5.0, 0.5, Field2D::spectral});
  EXPECT_TRUE(r.irregularity_identifiable);
  EXPECT_NEAR(r.spec.central_pitch.value(), 0.0, kWidePitchTolerance);
  EXPECT_NEAR(r.spec.irregularity.value(), 5.0, kIrregularityTolerance);
}

// Texel cells: the lattice of cell borders gives the texel length exactly,
// the design is kept, and Central Pitch comes back.
TEST(Encode2D, CellsRoundTripFindsTheTexelLength) {
  const codec::Encode2DResult r = round_trip({3.0, -5.0, 0.5, Field2D::cells});
  EXPECT_TRUE(r.texel_length_detected);
  EXPECT_DOUBLE_EQ(r.spec.texel_length.value(), 0.5);
  EXPECT_EQ(r.field, Field2D::cells);
  EXPECT_NEAR(r.spec.central_pitch.value(), 3.0, kCellsPitchTolerance);
}

// A grating along 30°: its scans follow the cosine law, so the encoder
// reports it anisotropic, strongest across its lines.
TEST(Encode2D, OrientedGratingIsReportedAnisotropic) {
  const codec::Encode2DResult r = codec::encode_surface2d(
      render(texture_document(3.0, -10.0, 0.5, Field2D::oriented, ConstantProfile{}, 0.0, 1.0, 30.0)), quick_config());
  EXPECT_TRUE(r.anisotropic);
  EXPECT_GT(r.central_pitch_spread_db, 5.0);
  EXPECT_NEAR(r.strongest_direction_deg, 30.0, 15.0);
  EXPECT_NE(codec::to_json(r).find("\"anisotropic\": true"), std::string::npos);
}

// --- the coarse profile ----------------------------------------------------------

// A disc of higher friction (coarse strength 0.8, fine 0.6) appears in the
// coarse image at its place, and the written document renders again.
TEST(Encode2D, CoarseDiscAppearsAtItsPlace) {
  const Disc2D disc{Millimetres(4.0), Millimetres(7.0), Millimetres(3.0), Millimetres(0.5), 1.0, 0.0};
  const Raster2D map = render(texture_document(3.0, -5.0, 0.5, Field2D::spectral, disc, 0.8, 0.6));
  codec::Encode2DConfig cfg = quick_config();
  cfg.coarse_image_path = "disc.coarse.npy";
  const codec::Encode2DResult r = codec::encode_surface2d(map, cfg);
  ASSERT_TRUE(r.coarse);
  ASSERT_TRUE(r.coarse_image);
  std::printf("disc: C %.3f F %.3f P %.2f\n", r.spec.coarse_strength, r.spec.fine_strength, r.spec.central_pitch.value());
  EXPECT_NEAR(r.spec.coarse_strength, 0.8, 0.1);
  EXPECT_NEAR(r.spec.fine_strength, 0.6, 0.15);
  const Raster2D& img = *r.coarse_image;
  const auto c_at = [&](double x, double y) {
    const int i = std::clamp(static_cast<int>(x / (kSide * kPitch) * img.width), 0, img.width - 1);
    const int j = std::clamp(static_cast<int>(y / (kSide * kPitch) * img.height), 0, img.height - 1);
    return img.at(i, j);
  };
  EXPECT_GT(c_at(4.0, 7.0), 0.8);    // the disc's centre
  EXPECT_LT(c_at(10.5, 2.0), 0.25);  // far outside
  // The rim: c crosses one half within a window's width of 3 mm from the centre, along x.
  double crossing = 0.0;
  for (double x = 4.0; x < 12.0; x += 0.05)
    if (c_at(x, 7.0) < 0.5) {
      crossing = x - 4.0;
      break;
    }
  EXPECT_NEAR(crossing, 3.0, 0.6);

  TempDir dir("encode2d");
  const std::string doc_path = dir.at("disc.texel.json");
  codec::write_encoding2d(r, doc_path);
  EXPECT_EQ(dir.listing(), (std::set<std::string>{"disc.texel.json", "disc.coarse.npy"}));
  const Document back = load_document(doc_path);
  const Raster2D again = render_raster(prepare_surface2d(back));
  EXPECT_EQ(again.width, kSide);
  // The re-rendered map is brighter in the disc than outside, as the input.
  const auto mean_near = [&](const Raster2D& m, double x, double y) {
    double sum = 0.0;
    int n = 0;
    for (int j = 0; j < m.height; ++j)
      for (int i = 0; i < m.width; ++i)
        if (std::hypot(i * kPitch - x, j * kPitch - y) < 1.0) {
          sum += m.at(i, j);
          ++n;
        }
    return sum / n;
  };
  EXPECT_NEAR(mean_near(again, 4.0, 7.0), mean_near(map, 4.0, 7.0), 0.06);
  EXPECT_NEAR(mean_near(again, 10.5, 2.0), mean_near(map, 10.5, 2.0), 0.06);
}

// --- inputs ---------------------------------------------------------------------

// A small coarse feature on a large map is still found, in its place: a
// 1.5 mm disc on 40 × 40 mm covers about 1 % of it, even smoothed by the
// envelope's window (a 10 mm disc on a tablet is under 1 %).
TEST(Encode2D, SmallCoarseDiscOnALargeMapIsFound) {
  constexpr int side = 800;
  const Disc2D disc{Millimetres(20.0), Millimetres(20.0), Millimetres(1.5), Millimetres(0.2), 1.0, 0.0};
  Document doc = texture_document(3.0, -5.0, 0.5, Field2D::spectral, disc, 0.8, 0.6);
  doc.device = grid_device(side, side);
  const Raster2D map = render(doc);
  codec::Encode2DConfig cfg = quick_config();
  cfg.directions = 4;
  cfg.correction_rounds = 0;
  cfg.coarse_image_path = "small.coarse.npy";
  const codec::Encode2DResult r = codec::encode_surface2d(map, cfg);
  ASSERT_TRUE(r.coarse);
  ASSERT_TRUE(r.coarse_image);
  const Raster2D& img = *r.coarse_image;
  const auto c_at = [&](double x, double y) {
    const int i = std::clamp(static_cast<int>(x / (side * kPitch) * img.width), 0, img.width - 1);
    const int j = std::clamp(static_cast<int>(y / (side * kPitch) * img.height), 0, img.height - 1);
    return img.at(i, j);
  };
  EXPECT_GT(c_at(20.0, 20.0), c_at(5.0, 5.0) + 0.3);  // the disc stands out where it is
  EXPECT_LT(c_at(35.0, 35.0), 0.25);
}

TEST(Encode2D, PngEightAndSixteenBitAndNpyReadAsTheMap) {
  TempDir dir("encode2d");
  Document doc = texture_document(3.0, -5.0, 0.5, Field2D::spectral, ConstantProfile{}, 0.3, 0.8);
  const Raster2D map = render(doc);
  codec::Raster2DLoadOptions lo;
  lo.pitch = Millimetres(kPitch);
  for (int depth : {8, 16}) {
    BitmapFileOptions o;
    o.depth = depth;
    const std::string png = dir.at("map" + std::to_string(depth) + ".png");
    write_bitmap(png, prepare_surface2d(doc), o);
    EXPECT_TRUE(codec::is_2d_input(png));
    const codec::Input2D in = codec::load_input2d(png, lo);
    EXPECT_EQ(in.depth, depth);
    ASSERT_EQ(in.map.width, kSide);
    ASSERT_EQ(in.map.height, kSide);
    EXPECT_DOUBLE_EQ(in.map.pitch.value(), kPitch);
    double worst = 0.0;
    for (std::size_t k = 0; k < map.values.size(); ++k)
      worst = std::max(worst, std::abs(double(in.map.values[k]) - map.values[k]));
    EXPECT_LE(worst, 0.5 / ((1 << depth) - 1) + 1e-6) << depth;
  }
  // Polarity: brighter_more_friction stores 1 − a; reading it so gives a back.
  DeviceProfile bright = grid_device();
  bright.bitmap->polarity = BitmapPolarity::brighter_more_friction;
  doc.device = bright;
  const std::string inv = dir.at("inverted.png");
  write_bitmap(inv, prepare_surface2d(doc));
  codec::Raster2DLoadOptions bo;
  bo.device = bright;
  const codec::Input2D back = codec::load_input2d(inv, bo);
  EXPECT_EQ(back.polarity, BitmapPolarity::brighter_more_friction);
  EXPECT_NEAR(back.map.values[1000], map.values[1000], 1.0 / 65535 + 1e-6);
  // .npy (float64, rows along y): the values themselves.
  const std::string npy = dir.at("map.npy");
  write_bitmap(npy, prepare_surface2d(texture_document(3.0, -5.0, 0.5, Field2D::spectral, ConstantProfile{}, 0.3, 0.8)));
  EXPECT_TRUE(codec::is_2d_input(npy));
  const codec::Input2D n = codec::load_input2d(npy, lo);
  EXPECT_EQ(n.depth, 0);
  EXPECT_EQ(n.map.values, map.values);
  // A 1-D .npy is not a 2-D input (the 1-D encoder reads it).
  const std::vector<double> line(100, 0.5);
  write_file_atomic(dir.at("line.npy"), npy_bytes(line));
  EXPECT_FALSE(codec::is_2d_input(dir.at("line.npy")));
}

// A height map (values outside [0, 1], µm) is scaled as the 1-D encoder
// scales maps, and encodes to the same texture as its amplitudes.
TEST(Encode2D, HeightMapIsScaled) {
  TempDir dir("encode2d");
  const Raster2D map = render(texture_document(3.0, -5.0, 0.5, Field2D::spectral));
  std::string bytes = npy_header(kSide, kSide);
  for (float v : map.values) {
    const double height_um = 40.0 * (v - 0.5);  // ±20 µm
    bytes.append(reinterpret_cast<const char*>(&height_um), sizeof height_um);
  }
  write_file_atomic(dir.at("height.npy"), bytes);
  codec::Raster2DLoadOptions lo;
  lo.pitch = Millimetres(kPitch);
  const codec::Input2D in = codec::load_input2d(dir.at("height.npy"), lo);
  float lo_v = 1.0f, hi_v = 0.0f;
  for (float v : in.map.values) {
    lo_v = std::min(lo_v, v);
    hi_v = std::max(hi_v, v);
  }
  EXPECT_GE(lo_v, 0.0f);
  EXPECT_LE(hi_v, 1.0f);
  EXPECT_NEAR(std::max(hi_v - 0.5f, 0.5f - lo_v), 0.5f, 1e-3f);
}

// A bundle of 1-D scans along 0°, 60° and 120° of one surface: long
// straight swipes across the field, as a profilometer or a finger records them.
TEST(Encode2D, ScanBundleEncodes) {
  TempDir dir("encode2d");
  const Document doc = texture_document(3.0, -5.0, 0.5, Field2D::spectral);
  const Region2DSpec& region = doc.surface2d->regions[0];
  const FineField2D field(region.texel, Field2D::spectral, 0.0, CyclesPerMm(0.5 / kPitch));
  std::string bundle = R"({"format": "texel-scans", "version": 1, "width_mm": 25.6, "height_mm": 25.6, "scans": [)";
  for (int k = 0; k < 3; ++k) {
    const double th = k * 60.0 * 3.14159265358979 / 180.0;
    std::vector<double> scan(8192);
    for (std::size_t s = 0; s < scan.size(); ++s)
      scan[s] = 0.5 + 0.5 * field.value(s * kPitch * std::cos(th) + 3.0 * k, s * kPitch * std::sin(th) + 7.0 * k);
    const std::string name = "scan" + std::to_string(k) + ".npy";
    write_file_atomic(dir.at(name), npy_bytes(scan));
    bundle += std::string(k ? ", " : "") + R"({"path": ")" + name + R"(", "direction_deg": )" + std::to_string(k * 60) + "}";
  }
  bundle += "]}";
  const std::string path = dir.write("s.scans.json", bundle);
  SignalOptions so;
  so.spacing = Millimetres(kPitch);
  const codec::ScanBundle b = codec::load_scan_bundle(path, so);
  ASSERT_EQ(b.scans.size(), 3u);
  EXPECT_DOUBLE_EQ(b.scans[1].direction_deg, 60.0);
  const codec::Encode2DResult r = codec::encode_scans(b, quick_config());
  std::printf("scans: P %.2f I %.2f identifiable %d, spread P %.2f dB\n", r.spec.central_pitch.value(),
              r.spec.irregularity.value(), r.irregularity_identifiable, r.central_pitch_spread_db);
  EXPECT_EQ(r.method, "scans");
  EXPECT_EQ(r.per_direction.size(), 3u);
  EXPECT_NEAR(r.spec.central_pitch.value(), 3.0, kScansPitchTolerance);
  EXPECT_NEAR(r.document.device.bitmap->width_mm().value(), 25.6, 0.06);
}

// --- errors -----------------------------------------------------------------------

TEST(Encode2D, InvalidInputsGiveClearErrors) {
  TempDir dir("encode2d");
  const Raster2D map = render(texture_document(3.0, -5.0, 0.5, Field2D::spectral));
  const std::string png = dir.at("m.png");
  write_bitmap(png, prepare_surface2d(texture_document(3.0, -5.0, 0.5, Field2D::spectral)));
  EXPECT_NE(message_of<InvalidArgument>([&] { codec::load_input2d(png, {}); }).find("--pitch"), std::string::npos);
  codec::Raster2DLoadOptions tpad;
  tpad.device = load_device("tpad");
  EXPECT_NE(message_of<InvalidArgument>([&] { codec::load_input2d(png, tpad); }).find("has no bitmap"), std::string::npos);
  codec::Raster2DLoadOptions bad_pitch;
  bad_pitch.pitch = Millimetres(-1.0);
  EXPECT_NE(message_of<InvalidArgument>([&] { codec::load_input2d(png, bad_pitch); }).find("must be > 0"), std::string::npos);
  // A 3-D .npy, NaN values.
  write_file_atomic(dir.at("cube.npy"), npy_header_for_shape("2, 2, 2") + std::string(64, '\0'));
  codec::Raster2DLoadOptions lo;
  lo.pitch = Millimetres(kPitch);
  EXPECT_NE(message_of<FormatError>([&] { codec::load_input2d(dir.at("cube.npy"), lo); }).find("two-dimensional"),
            std::string::npos);
  std::string nan_bytes = npy_header(2, 2);
  const double nan = std::nan(""), zero = 0.0;
  for (double v : {zero, nan, zero, zero}) nan_bytes.append(reinterpret_cast<const char*>(&v), 8);
  write_file_atomic(dir.at("nan.npy"), nan_bytes);
  EXPECT_NE(
      message_of<FormatError>([&] { codec::load_input2d(dir.at("nan.npy"), lo); }).find("non-finite value (nan at element 1)"),
      std::string::npos);
  // Maps: too small, outside [0, 1], a device it does not fit.
  Raster2D tiny;
  tiny.width = tiny.height = 8;
  tiny.values.assign(64, 0.5f);
  EXPECT_NE(message_of<InvalidArgument>([&] { codec::encode_surface2d(tiny, quick_config()); }).find("at least 16 × 16"),
            std::string::npos);
  // A map outside [0, 1] is read by the one input rule (texel::to_amplitudes): scaled to full range, never refused
  // or clamped; a constant one outside holds no texture.
  Raster2D out = map;
  out.values[5] = 1.5f;
  std::vector<double> scaled(out.values.begin(), out.values.end());
  EXPECT_TRUE(to_amplitudes(scaled, "the map"));
  Raster2D in_range = out;
  in_range.values.assign(scaled.begin(), scaled.end());
  EXPECT_EQ(document_json(codec::encode_surface2d(out, quick_config()).document),
            document_json(codec::encode_surface2d(in_range, quick_config()).document));
  Raster2D constant = map;
  constant.values.assign(constant.values.size(), 2.0f);
  EXPECT_NE(message_of<FormatError>([&] { codec::encode_surface2d(constant, quick_config()); }).find("holds no texture"),
            std::string::npos);
  codec::Encode2DConfig small_device;
  small_device.device = grid_device(100, 100);
  EXPECT_NE(message_of<InvalidArgument>([&] { codec::encode_surface2d(map, small_device); }).find("larger than device"),
            std::string::npos);
  codec::Encode2DConfig bad;
  bad.directions = 1;
  EXPECT_NE(message_of<InvalidArgument>([&] { codec::encode_surface2d(map, bad); }).find("directions is 1"), std::string::npos);
  // Bundles: a bad field names its JSON path and the file.
  const std::string b1 = dir.write(
      "b.scans.json", R"({"format": "texel-scans", "version": 1, "scans": [{"path": "x.npy", "direction_deg": "east"}]})");
  const std::string m1 = message_of<FormatError>([&] { codec::load_scan_bundle(b1, SignalOptions{}); });
  EXPECT_NE(m1.find("b.scans.json: scans[0].direction_deg must be a number"), std::string::npos) << m1;
  const std::string b2 = dir.write("c.scans.json", R"({"format": "texel-scans", "version": 1, "scans": []})");
  EXPECT_NE(message_of<FormatError>([&] { codec::load_scan_bundle(b2, SignalOptions{}); }).find("non-empty"), std::string::npos);
  // A constant map has no texture: flagged, or refused on request.
  Raster2D flat = map;
  std::fill(flat.values.begin(), flat.values.end(), 0.7f);
  const codec::Encode2DResult f = codec::encode_surface2d(flat, quick_config());
  EXPECT_TRUE(f.no_texture);
  EXPECT_NEAR(f.spec.coarse_strength, 0.3, 1e-6);
  codec::Encode2DConfig refuse;
  refuse.encoder.no_texture = codec::EncoderConfig::NoTexture::refuse;
  EXPECT_NE(message_of<InvalidArgument>([&] { codec::encode_surface2d(flat, refuse); }).find("no texture"), std::string::npos);
}
