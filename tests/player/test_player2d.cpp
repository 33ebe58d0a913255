// The 2-D player (issue #26 part 4): path-indexed fine texture felt the same
// along every path at one speed, coarse features and bitmaps at their (x, y),
// frequencies limited below the drive's Nyquist, the [choice] path at lift,
// and the 2-D paths and trace reader.
#include <gtest/gtest.h>

#include "../support/log_centroid.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "../support/alloc_counter.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/player.hpp"
#include "texel/player2d.hpp"
#include "texel/spectrum.hpp"

namespace {

using namespace texel;

constexpr double rate = 48000.0;
constexpr double speed = 100.0;    // mm/s
constexpr double duration = 0.9;   // s: within one pass of the tpad map
constexpr double settle_s = 0.05;  // skip the touch-down ramp and filter settling

/// The log-spectral centroid (tests/support/log_centroid.hpp) of the output
/// after `settle_s`.
double log_centroid_db(const std::vector<float>& y) {
  const auto skip = static_cast<std::size_t>(settle_s * rate);
  const auto end = static_cast<std::size_t>(duration * rate);
  const std::vector<double> x(y.begin() + static_cast<std::ptrdiff_t>(skip), y.begin() + static_cast<std::ptrdiff_t>(end));
  return test_support::log_centroid_db(x, rate);
}

PlayerConfig vibration() {
  PlayerConfig c;
  c.rate_hz = rate;
  c.mode = OutputMode::vibration;
  return c;
}

Raster2D disc(double radius_mm) {  // 1 inside a disc at (0, 0), 0 outside; 0.5 mm pitch over ±50 mm
  Raster2D r;
  r.width = r.height = 200;
  r.pitch = Millimetres(0.5);
  r.origin_x = r.origin_y = Millimetres(-50.0);
  r.values.resize(200 * 200);
  for (int j = 0; j < 200; ++j)
    for (int i = 0; i < 200; ++i) {
      const double x = -50.0 + 0.5 * i, y = -50.0 + 0.5 * j;
      r.values[static_cast<std::size_t>(j * 200 + i)] = std::hypot(x, y) < radius_mm ? 1.0f : 0.0f;
    }
  return r;
}

const Extent2D wide{-500.0, -500.0, 1000.0, 1000.0};

TEST(Player2D, PathIndexedTextureFeelsTheSameAlongEveryPath) {
  for (double pitch : {5.0, 10.0, 15.0}) {
    TexelSpec spec;
    spec.central_pitch = Decibels(pitch);
    spec.irregularity = Decibels(-5.0);
    spec.texel_length = Millimetres(0.25);
    const Document doc = make_document(load_device("tpad"), spec);
    const Surface surface = prepare_surface(doc);
    // The 1-D swipe: one stroke over the tpad map at 100 mm/s.
    SwipeConfig sc;
    sc.speed_mm_s = speed;
    sc.surface_mm = surface.grid().length().value();
    sc.duration_s = duration;
    const auto trace1 = simulate_swipe(sc);
    const auto frames = static_cast<std::size_t>(duration * rate);
    const auto map1 = PlayerMap::from_surface(surface);
    const double ref = log_centroid_db(render_trace(*map1, vibration(), trace1, frames));

    const auto map2 = PlayerMap2D::path_indexed(spec, Sampling{surface.grid(), CyclesPerMm(0.0)}, std::nullopt, wide);
    std::vector<Path2DConfig> paths;
    for (double angle : {0.0, 30.0, 45.0, 90.0, 135.0, 200.0, 315.0}) {
      Path2DConfig p;
      p.angle_deg = angle;
      paths.push_back(p);
    }
    Path2DConfig circle;
    circle.shape = Path2DShape::circle;
    circle.radius_mm = 10.0;
    paths.push_back(circle);
    for (double leg : {2.0, 10.0}) {
      Path2DConfig zz;
      zz.shape = Path2DShape::zigzag;
      zz.leg_mm = leg;
      zz.angle_deg = 20.0;
      paths.push_back(zz);
    }
    double worst = 0;
    for (Path2DConfig p : paths) {
      p.speed_mm_s = speed;
      p.duration_s = duration;
      const auto trace = simulate_path_2d(p);
      const double c = log_centroid_db(render_trace_2d(*map2, vibration(), trace, frames));
      EXPECT_NEAR(c, ref, 0.3) << "P " << pitch << " dB, path " << to_string(p.shape) << " angle " << p.angle_deg << " leg "
                               << p.leg_mm;
      worst = std::max(worst, std::fabs(c - ref));
    }
    std::printf("P %.0f dB: 1-D centroid %.3f dB; largest 2-D path difference %.4f dB over %zu paths\n", pitch, ref, worst,
                paths.size());
  }
}

TEST(Player2D, CoarseFeaturesAppearAtTheirPositionsToTheSample) {
  TexelSpec spec;
  spec.coarse_strength = 1.0;
  spec.fine_strength = 0.0;  // a = c: the coarse raster alone
  PlayerConfig c;
  c.rate_hz = rate;  // amplitude mode, no response limit: the value under the finger itself
  const Raster2D r = disc(10.0);
  const auto map =
      PlayerMap2D::path_indexed(spec, Sampling{Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, {}}, r, std::nullopt);
  for (double angle : {0.0, 37.0, 90.0, 225.0}) {
    Path2DConfig p;
    p.angle_deg = angle;
    const double th = angle * std::numbers::pi / 180;
    p.start_x_mm = -30.0 * std::cos(th);  // crosses the disc through its centre
    p.start_y_mm = -30.0 * std::sin(th);
    p.duration_s = 0.55;
    const auto frames = static_cast<std::size_t>(0.5 * rate);
    std::vector<float> x, y;
    const auto out = render_trace_2d(*map, c, simulate_path_2d(p), frames, &x, &y);
    const auto ramp = static_cast<std::size_t>(c.touch_ramp_s * rate) + 2;
    std::size_t first_in = 0, first_out = 0;
    for (std::size_t i = ramp; i < frames; ++i) {
      ASSERT_NEAR(out[i], sample_bilinear(r, x[i], y[i]), 1e-6) << "sample " << i << " angle " << angle;
      if (!first_in && out[i] >= 0.5f) first_in = i;
      if (first_in && !first_out && out[i] < 0.5f) first_out = i;
    }
    // The disc's edge (radius 10 mm, ±one raster pitch) at 100 mm/s from 30 mm out:
    // entered at 0.2 s, left at 0.4 s.
    EXPECT_NEAR(static_cast<double>(first_in) / rate, 0.2, 0.5 / speed) << angle;
    EXPECT_NEAR(static_cast<double>(first_out) / rate, 0.4, 0.5 / speed) << angle;
  }
}

TEST(Player2D, BitmapIsTheRasterAtTheFinger) {
  PlayerConfig c;
  c.rate_hz = rate;
  Raster2D r = disc(15.0);
  for (std::size_t k = 0; k < r.values.size(); ++k) r.values[k] = 0.2f + 0.6f * r.values[k];
  const auto map = PlayerMap2D::bitmap(r);
  Path2DConfig p;
  p.shape = Path2DShape::zigzag;
  p.start_x_mm = -40.0;
  p.leg_mm = 7.0;
  p.duration_s = 0.8;
  const auto frames = static_cast<std::size_t>(0.75 * rate);
  std::vector<float> x, y;
  const auto out = render_trace_2d(*map, c, simulate_path_2d(p), frames, &x, &y);
  double lo = 1, hi = 0;
  for (std::size_t i = 300; i < frames; ++i) {
    ASSERT_NEAR(out[i], sample_bilinear(r, x[i], y[i]), 1e-6) << i;
    lo = std::min<double>(lo, out[i]), hi = std::max<double>(hi, out[i]);
  }
  EXPECT_NEAR(lo, 0.2, 1e-6);
  EXPECT_NEAR(hi, 0.8, 1e-6);
  // Off the raster the finger counts as lifted: ramped to 0.
  p.start_x_mm = -49.9;
  p.shape = Path2DShape::line;
  p.angle_deg = 180.0;
  p.duration_s = 0.1;
  const auto off = render_trace_2d(*map, c, simulate_path_2d(p), 4800);
  EXPECT_EQ(off.back(), 0.0f);
}

TEST(Player2D, NoContentAboveTheDrivesNyquistAtAnySpeed) {
  TexelSpec spec;
  spec.central_pitch = Decibels(20.0);  // 100 cycles/mm
  spec.irregularity = Decibels(-20.0);
  spec.texel_length = Millimetres(0.25);
  PlayerConfig c;
  c.rate_hz = rate;  // amplitude: 0.5 + 0.5·w·s
  const Grid fine_grid{Millimetres(0.0), Millimetres(0.001), 100000};
  const auto map = PlayerMap2D::path_indexed(spec, Sampling{fine_grid, {}}, std::nullopt, wide);
  const auto spread = [&](double v) {
    Path2DConfig p;
    p.speed_mm_s = v;
    p.angle_deg = 60.0;
    p.duration_s = 0.2;
    const auto out = render_trace_2d(*map, c, simulate_path_2d(p), 9000);
    double d = 0;
    for (std::size_t i = 1000; i < out.size(); ++i) d = std::max(d, static_cast<double>(std::fabs(out[i] - 0.5f)));
    return d;
  };
  EXPECT_GT(spread(100.0), 0.4);   // 10 kHz: played
  EXPECT_LT(spread(400.0), 1e-6);  // 40 kHz > 0.45·48 kHz: faded out, not aliased
}

TEST(Player2D, PathAtLiftKeepOrReset) {
  TexelSpec spec;
  const auto map =
      PlayerMap2D::path_indexed(spec, Sampling{Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, {}}, std::nullopt, wide);
  // Two identical strokes 0.3 s apart.
  std::vector<FingerSample2D> trace;
  for (int stroke = 0; stroke < 2; ++stroke) {
    const double t0 = 0.3 * stroke;
    for (int i = 0; i <= 200; ++i) trace.push_back({t0 + i * 1e-3, 0.1 * i, 0.0, true});
    trace.push_back({t0 + 0.201, 20.0, 0.0, false});
  }
  PlayerConfig c;
  c.rate_hz = rate;
  for (PathAtLift at : {PathAtLift::keep, PathAtLift::reset}) {
    const auto out = render_trace_2d(*map, c, trace, static_cast<std::size_t>(0.55 * rate), nullptr, nullptr, 64, at);
    double diff = 0;
    for (std::size_t i = 1000; i < 9000; ++i) diff = std::max(diff, static_cast<double>(std::fabs(out[i] - out[i + 14400])));
    if (at == PathAtLift::reset)
      EXPECT_LT(diff, 1e-5) << "reset: the second stroke repeats the first";
    else
      EXPECT_GT(diff, 0.1) << "keep: the second stroke continues the texture";
  }
  EXPECT_EQ(parse_path_at_lift("reset"), PathAtLift::reset);
  EXPECT_THROW(parse_path_at_lift("restart"), InvalidArgument);
}

TEST(Player2D, InputsAreValidated) {
  TexelSpec spec;
  const Sampling s{Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, {}};
  EXPECT_THROW(PlayerMap2D::path_indexed(spec, s, std::nullopt, std::nullopt), InvalidArgument);
  Raster2D bad = disc(5.0);
  bad.values[7] = 1.5f;
  EXPECT_THROW(PlayerMap2D::bitmap(bad), InvalidArgument);
  bad.values.pop_back();
  EXPECT_THROW(PlayerMap2D::bitmap(bad), InvalidArgument);
  EXPECT_THROW(PlayerMap2D::path_indexed(spec, s, std::nullopt, Extent2D{0, 0, 10, 10}, 0.01), InvalidArgument);
  Path2DConfig p;
  p.speed_mm_s = 0;
  EXPECT_THROW(simulate_path_2d(p), InvalidArgument);
  const auto t = parse_trace_2d_csv("time_s,x_mm,y_mm,touch\n0,1,2,1\n0.001,1.1,2.1,0\n", "t.csv");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_DOUBLE_EQ(t[1].y_mm, 2.1);
  EXPECT_FALSE(t[1].touch);
  EXPECT_THROW(parse_trace_2d_csv("0,1,2\n-1,1,2\n", "t.csv"), FormatError);
  EXPECT_THROW(parse_trace_2d_csv("0,1\n", "t.csv"), FormatError);
}

std::string npy(const std::string& shape, std::size_t count) {
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': " + shape + ", }";
  header.append(128 - 10 - header.size() - 1, ' ');
  header.push_back('\n');
  std::string bytes("\x93NUMPY\x01\x00", 8);
  bytes.push_back(static_cast<char>(header.size()));
  bytes.push_back('\0');
  bytes += header;
  for (std::size_t k = 0; k < count; ++k) {
    const float v = 0.1f * static_cast<float>(k);
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  return bytes;
}

TEST(Player2D, RasterFromNpyRowsAlongY) {
  const Raster2D r = parse_raster_npy(npy("(2, 3)", 6), "r.npy", Millimetres(0.5), Millimetres(1.0), Millimetres(2.0));
  EXPECT_EQ(r.width, 3);
  EXPECT_EQ(r.height, 2);
  EXPECT_FLOAT_EQ(r.at(2, 1), 0.5f);                                       // row 1 (y), column 2 (x): element 5
  EXPECT_NEAR(sample_bilinear(r, 1.0 + 2 * 0.5, 2.0 + 0.25), 0.35, 1e-6);  // halfway between rows at x = column 2
  EXPECT_THROW(parse_raster_npy(npy("(2, 2, 2)", 8), "r.npy", Millimetres(0.5)), FormatError);
  EXPECT_THROW(parse_raster_npy(npy("(6,)", 6), "r.npy", Millimetres(0.5)), FormatError);
  EXPECT_THROW(parse_raster_npy(npy("(4, 3)", 6), "r.npy", Millimetres(0.5)), FormatError);  // data short
  EXPECT_THROW(parse_npy(npy("(2, 3)", 6), "r.npy"), FormatError);                           // the 1-D reader still wants 1-D
}

// The fine texture's sine is detmath's (docs/player.md §2): against the
// C library's sin(2π·u) at the same texel and phase it differs by < 1e-14.
TEST(Player2D, FineTextureMatchesTheCLibrarySine) {
  TexelSpec spec;
  spec.central_pitch = Decibels(15.0);
  const Sampling s{Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, {}};
  constexpr double strip = 40.0;
  const auto map = PlayerMap2D::path_indexed(spec, s, std::nullopt, wide, strip);
  // The same texels as the map's (the 1-D renderer's, same seed).
  TexelSpec texels = spec;
  texels.coarse_strength = 0.0;
  texels.fill = Fill::whole_texels;
  const TexelTexture texture(texels, Millimetres(strip), s);
  double worst = 0.0;
  std::size_t checked = 0;
  texture.for_each_texels([&](std::size_t, std::span<const Texel> run) {
    for (const Texel& t : run)
      for (double f : {0.1, 0.37, 0.5, 0.93}) {
        const double at = t.start.value() + f * spec.texel_length.value();
        const double u = t.phase_cycles + t.frequency.value() * (at - t.start.value());
        worst = std::max(worst, std::fabs(map->fine(at, 0.0, 1e12) - std::sin(2.0 * std::numbers::pi * u)));
        ++checked;
      }
  });
  EXPECT_GT(checked, 400u);
  EXPECT_LT(worst, 1e-14);
}

// process() in blocks of any length gives the same samples (the passes over
// a block change no value): 1, 16, 64 and 100 frames (a chunk of 64 and one
// of 36), path-indexed with a coarse raster and bitmap, every output mode.
TEST(Player2D, OutputIsTheSameForEveryBlockLength) {
  TexelSpec spec;
  spec.coarse_strength = 0.5;
  const Sampling s{Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, {}};
  const auto path = PlayerMap2D::path_indexed(spec, s, disc(10.0), std::nullopt);
  const auto bitmap = PlayerMap2D::bitmap(disc(10.0));
  Path2DConfig p;
  p.shape = Path2DShape::circle;
  p.radius_mm = 10.0;  // crosses the disc's edge
  p.start_x_mm = 3.0;
  p.duration_s = 0.1;
  const auto trace = simulate_path_2d(p);
  for (OutputMode mode : {OutputMode::vibration, OutputMode::carrier, OutputMode::amplitude})
    for (const auto* map : {path.get(), bitmap.get()}) {
      PlayerConfig c;
      c.rate_hz = rate;
      c.mode = mode;
      c.carrier_hz = mode == OutputMode::carrier ? 200.0 : 0.0;
      const auto one = render_trace_2d(*map, c, trace, 6000, nullptr, nullptr, 1);
      for (std::size_t block : {16, 64, 100}) {
        const auto out = render_trace_2d(*map, c, trace, 6000, nullptr, nullptr, block);
        ASSERT_EQ(std::memcmp(one.data(), out.data(), one.size() * sizeof(float)), 0) << to_string(mode) << ", block " << block;
      }
    }
}

// process() allocates and frees nothing while another thread streams finger
// samples, changes gain and swaps maps (path-indexed with and without a
// coarse raster and a display response, bitmaps) as fast as they are taken.
TEST(Player2D, ProcessNeverAllocatesWhileSwapping) {
  using namespace texel::test_support::alloc;
  constexpr std::uint64_t blocks = 30000;
  constexpr std::size_t frames = 16;
  TexelSpec spec;
  spec.coarse_strength = 0.5;
  const Sampling s{Grid{Millimetres(0.0), Millimetres(0.0053), 19200}, {}};
  const auto path = PlayerMap2D::path_indexed(spec, s, disc(20.0), std::nullopt, 2000.0);
  const auto plain =
      PlayerMap2D::path_indexed(spec, s, std::nullopt, wide, 2000.0, FrequencyResponse{Hertz(300.0), 2, "2nd order"});
  const auto bitmap = PlayerMap2D::bitmap(disc(30.0));
  for (OutputMode mode : {OutputMode::vibration, OutputMode::carrier, OutputMode::amplitude}) {
    PlayerConfig c;
    c.rate_hz = rate;
    c.mode = mode;
    c.crossfade_s = 0.002;
    c.prediction_s = 0.02;
    Player2D player(c, std::make_unique<const PlayerMap2D>(*path));
    std::atomic<std::uint64_t> done{0};
    std::atomic<bool> stop{false};
    std::uint64_t swaps = 0;
    std::thread control([&] {
      double t = 0;
      while (!stop.load(std::memory_order_relaxed)) {
        const double now = static_cast<double>(done.load(std::memory_order_relaxed)) * frames / rate;
        while (t < now + 0.05 && player.push({t, 30 * std::cos(3 * t), 30 * std::sin(5 * t), std::fmod(t, 0.5) < 0.45}))
          t += 0.001;
        player.set_gain(0.5 + 0.5 * std::sin(t));
        const PlayerMap2D& next = swaps % 3 == 0 ? *plain : swaps % 3 == 1 ? *bitmap : *path;
        player.set_map(std::make_unique<const PlayerMap2D>(next));
        ++swaps;
        player.collect();
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
    });
    std::vector<float> out(frames), x(frames), y(frames);
    const double sum = texel::test_support::alloc::count_blocks(blocks, done, [&] { return player.process(out, x, y).peak; });
    stop = true;
    control.join();
    EXPECT_EQ(counted_allocations.load(), 0u) << to_string(mode);
    EXPECT_EQ(counted_frees.load(), 0u) << to_string(mode);
    EXPECT_GT(swaps, 10u) << to_string(mode);
    EXPECT_GT(sum, 0.0) << to_string(mode);
  }
}

}  // namespace
