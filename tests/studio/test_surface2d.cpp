// The 2-D page's messages through the Service (docs/studio.md "The 2-D
// page"): surface2d.view renders exactly the bitmap's pixels at any stride,
// surface2d.scan gives a scan spectrum beside the 1-D texture's, the 2-D pad's
// finger samples reach the Player2D in both modes, coarse images come only as
// bytes sent along, and every bad input gets a one-line error. With a serial
// display (the reference controller on a pty), the pad plays on the studio's
// configured backend and hands the device over to and from the 1-D Feel-it
// strip without a click.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <thread>

#include <nlohmann/json.hpp>

#include "../support/display_rig.hpp"
#include "../support/service_client.hpp"
#include "../support/temp_dir.hpp"
#include "base64.hpp"
#include "texel/bitmap_file.hpp"
#include "texel/document.hpp"
#include "texel/studio/service.hpp"
#include "texel/studio/surface2d_view.hpp"
#include "texel/surface2d.hpp"

using json = nlohmann::json;
using namespace std::chrono_literals;
using texel::studio::Service;
using texel::studio::ServiceOptions;
using texel::test_support::Client;

namespace {

json surface_document(
    const json& coarse =
        json{{"kind", "disc"}, {"x_mm", 20}, {"y_mm", 15}, {"radius_mm", 8}, {"edge_mm", 1}, {"inside", 1}, {"outside", 0.2}},
    const std::string& field = "spectral") {
  const json device = {{"name", "pad-2d"},
                       {"samples", 400},
                       {"spacing_mm", 0.1},
                       {"format", "f32le"},
                       {"refresh_hz", 6250},
                       {"band_min_cpm", 0.01},
                       {"band_max_cpm", 0},
                       {"layout", json::array()},
                       {"bitmap",
                        {{"width_px", 400},
                         {"height_px", 300},
                         {"pixel_pitch_mm", 0.1},
                         {"depth_bits", 8},
                         {"polarity", "darker_more_friction"}}}};
  return json{{"format", "texel-document"},
              {"version", 4},
              {"device", device},
              {"surface2d",
               {{"regions",
                 {{{"name", "pad"},
                   {"field", field},
                   {"texture",
                    {{"kind", "texel"},
                     {"central_pitch_db", 0},
                     {"irregularity_db", -5},
                     {"texel_length_mm", 1},
                     {"seed", 3},
                     {"coarse_strength", 0.8},
                     {"fine_strength", 0.6}}},
                   {"coarse2d", coarse}}}}}}};
}

void expect_error(const json& r, const std::string& code, const std::string& names = "") {
  EXPECT_EQ(r.value("type", ""), "error") << r.dump();
  EXPECT_EQ(r.value("code", ""), code) << r.dump();
  EXPECT_EQ(r.value("message", "").find('\n'), std::string::npos);
  if (!names.empty()) {
    EXPECT_NE(r.value("message", "").find(names), std::string::npos) << r.dump();
  }
}

std::vector<unsigned char> bytes_of(const json& r) {
  return texel::studio::detail::base64_decode(r["amplitude_u8"].get<std::string>()).value();
}

}  // namespace

TEST(Surface2DStudio, ViewIsTheBitmapAtAnyStride) {
  Service s(ServiceOptions{});
  Client c(s);
  const json doc = surface_document();
  const json full = c.ask({{"type", "surface2d.view"},
                           {"document", doc},
                           {"x_px", 0},
                           {"y_px", 0},
                           {"width_px", 400},
                           {"height_px", 300},
                           {"stride", 1}});
  ASSERT_EQ(full["type"], "surface2d.view") << full.dump().substr(0, 300);
  EXPECT_EQ(full["columns"], 400);
  EXPECT_EQ(full["rows"], 300);
  EXPECT_DOUBLE_EQ(full["surface"]["pixel_pitch_mm"].get<double>(), 0.1);
  const auto all = bytes_of(full);
  ASSERT_EQ(all.size(), 400u * 300u);
  // The library's own bitmap of the document, pixel for pixel.
  const texel::Document d = texel::parse_document(doc.dump(), "doc");
  const texel::Raster2D raster = texel::render_raster(texel::prepare_surface2d(d));
  int differ = 0;
  for (std::size_t i = 0; i < all.size(); ++i)
    differ += std::abs(static_cast<int>(all[i]) - static_cast<int>(std::lround(raster.values[i] * 255.0))) > 1;
  EXPECT_EQ(differ, 0);
  // A window at stride 3 holds every third pixel of it; the reply says its clipped size.
  const json part = c.ask({{"type", "surface2d.view"},
                           {"document", doc},
                           {"x_px", 100},
                           {"y_px", 50},
                           {"width_px", 1000},
                           {"height_px", 90},
                           {"stride", 3}});
  ASSERT_EQ(part["type"], "surface2d.view");
  EXPECT_EQ(part["width_px"], 300);
  EXPECT_EQ(part["columns"], 100);
  EXPECT_EQ(part["rows"], 30);
  EXPECT_NEAR(part["view_pitch_mm"].get<double>(), 0.3, 1e-12);
  const auto some = bytes_of(part);
  differ = 0;
  for (int v = 0; v < 30; ++v)
    for (int u = 0; u < 100; ++u)
      differ += std::abs(static_cast<int>(some[static_cast<std::size_t>(v * 100 + u)]) -
                         static_cast<int>(all[static_cast<std::size_t>((50 + 3 * v) * 400 + 100 + 3 * u)])) > 1;
  EXPECT_EQ(differ, 0);
}

TEST(Surface2DStudio, BadInputsGetOneLineErrors) {
  Service s(ServiceOptions{});
  Client c(s);
  const json doc = surface_document();
  auto view = [&](json extra) {
    json m = {{"type", "surface2d.view"}, {"document", doc}, {"x_px", 0},  {"y_px", 0},
              {"width_px", 10},           {"height_px", 10}, {"stride", 1}};
    for (auto& [k, v] : extra.items()) m[k] = v;
    return c.ask(m);
  };
  expect_error(view({{"x_px", 400}}), "invalid", "x_px");
  expect_error(view({{"stride", 0}}), "invalid", "stride");
  expect_error(c.ask({{"type", "surface2d.view"},
                      {"document", doc},
                      {"x_px", 0},
                      {"y_px", 0},
                      {"width_px", 65535},
                      {"height_px", 65535},
                      {"stride", 1},
                      {"zoom", 2}}),
               "bad_message", "zoom");
  expect_error(c.ask({{"type", "surface2d.scan"}, {"document", doc}, {"angle_deg", 400}}), "invalid", "angle_deg");
  expect_error(c.ask({{"type", "surface2d.scan"}, {"document", doc}, {"angle_deg", 0}, {"region", 3}}), "invalid", "region");
  json one_d = {
      {"format", "texel-document"},
      {"version", 1},
      {"device", "tpad"},
      {"texture", {{"kind", "texel"}, {"central_pitch_db", 0}, {"irregularity_db", -5}, {"texel_length_mm", 1}, {"seed", 1}}}};
  expect_error(c.ask({{"type", "surface2d.scan"}, {"document", one_d}, {"angle_deg", 0}}), "invalid", "2-D document");
  expect_error(c.ask({{"type", "feel2d.select"}, {"document", doc}, {"mode", "hover"}}), "invalid", "mode");
  json odd = doc;
  odd["surface2d"]["regions"][0] = 7;
  expect_error(c.ask({{"type", "surface2d.scan"}, {"document", odd}, {"angle_deg", 0}}), "invalid", "regions[0]");
  odd["surface2d"] = "flat";
  expect_error(c.ask({{"type", "surface2d.scan"}, {"document", odd}, {"angle_deg", 0}}), "invalid", "surface2d");
  expect_error(c.ask({{"type", "feel2d.move"}, {"seq", 1}, {"x_mm", 1}}), "bad_message", "y_mm");
  // Image profiles: only bytes sent along, never a file of the server's.
  expect_error(c.ask({{"type", "surface2d.scan"},
                      {"document", surface_document({{"kind", "image"}, {"path", "/etc/passwd.png"}})},
                      {"angle_deg", 0}}),
               "invalid", "coarse2d.path");
  expect_error(c.ask({{"type", "surface2d.scan"}, {"document", doc}, {"angle_deg", 0}, {"images", {{"../x.png", "AAAA"}}}}),
               "invalid", "images key");
  expect_error(c.ask({{"type", "surface2d.scan"}, {"document", doc}, {"angle_deg", 0}, {"images", {{"x.png", "AAAA"}}}}),
               "invalid", "not a PNG");
}

TEST(Surface2DStudio, ImagesSentAlongBecomeTheCoarseProfile) {
  texel::test_support::TempDir dir("studio2d");
  // A 4 × 2 grey PNG through the library's own writer: a half-white, half-black image.
  const json black_white =
      surface_document({{"kind", "edge"}, {"x_mm", 20}, {"y_mm", 0}, {"angle_deg", 0}, {"width_mm", 0}, {"low", 0}, {"high", 1}});
  json small = black_white;
  small["device"]["bitmap"]["width_px"] = 4;
  small["device"]["bitmap"]["height_px"] = 2;
  small["device"]["bitmap"]["pixel_pitch_mm"] = 10.0;
  small["surface2d"]["regions"][0]["texture"]["coarse_strength"] = 1;
  small["surface2d"]["regions"][0]["texture"]["fine_strength"] = 0;
  small["surface2d"]["regions"][0]["texture"]["central_pitch_db"] = -18;  // inside the 10 mm grid's band
  small["surface2d"]["regions"][0]["texture"]["irregularity_db"] = -30;
  const texel::Document d = texel::parse_document(small.dump(), "small");
  const std::string png = dir.at("edge.png");
  texel::BitmapFileOptions o;
  texel::write_bitmap(png, texel::prepare_surface2d(d), o);
  std::ifstream in(png, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Service s(ServiceOptions{});
  Client c(s);
  json doc = surface_document({{"kind", "image"}, {"path", "edge.png"}});
  doc["surface2d"]["regions"][0]["texture"]["fine_strength"] = 0;
  doc["surface2d"]["regions"][0]["texture"]["coarse_strength"] = 1;
  const json r = c.ask({{"type", "surface2d.view"},
                        {"document", doc},
                        {"images", {{"edge.png", texel::studio::detail::base64_encode(bytes)}}},
                        {"x_px", 0},
                        {"y_px", 150},
                        {"width_px", 400},
                        {"height_px", 1},
                        {"stride", 1}});
  ASSERT_EQ(r["type"], "surface2d.view") << r.dump().substr(0, 400);
  const auto row = bytes_of(r);
  // The image stretches over the region: dark on the left, bright on the right (polarity aside).
  EXPECT_NE(static_cast<int>(row[10]), static_cast<int>(row[390]));
}

TEST(Surface2DStudio, ScanAlongADirectionBesideTheTarget) {
  Service s(ServiceOptions{});
  Client c(s);
  const json r = c.ask(
      {{"type", "surface2d.scan"}, {"document", surface_document(json{{"kind", "constant"}, {"value", 1}})}, {"angle_deg", 30}});
  ASSERT_EQ(r["type"], "surface2d.scan") << r.dump().substr(0, 300);
  EXPECT_GT(r["samples"].get<int>(), 200);
  EXPECT_EQ(r["scan"]["frequency_cpm"].size(), r["scan"]["magnitude_db"].size());
  EXPECT_GT(r["target"]["frequency_cpm"].size(), 10u);
  const double dx = r["to_mm"][0].get<double>() - r["from_mm"][0].get<double>();
  const double dy = r["to_mm"][1].get<double>() - r["from_mm"][1].get<double>();
  EXPECT_NEAR(std::atan2(dy, dx) * 180.0 / 3.141592653589793, 30.0, 1e-6);
}

TEST(Surface2DStudio, PadSamplesReachThe2DPlayerInBothModes) {
  Service s(ServiceOptions{});
  Client c(s);
  expect_error(c.ask({{"type", "feel2d.move"}, {"seq", 1}, {"x_mm", 10}, {"y_mm", 10}}), "invalid", "feel2d.select");
  for (const std::string mode : {"path", "bitmap"}) {
    const json sel = c.ask({{"type", "feel2d.select"}, {"document", surface_document()}, {"mode", mode}});
    ASSERT_EQ(sel["type"], "feel2d.selected") << sel.dump();
    EXPECT_EQ(sel["mode"], mode);
    c.ask({{"type", "feel2d.state"}});  // resets the peak
    for (int i = 0; i < 80; ++i) {
      const json a =
          c.ask({{"type", "feel2d.move"}, {"seq", i}, {"x_mm", 5.0 + 0.3 * i}, {"y_mm", 5.0 + 0.2 * i}, {"touch", true}});
      ASSERT_EQ(a["type"], "feel2d.ack") << a.dump();
      std::this_thread::sleep_for(1ms);
    }
    std::this_thread::sleep_for(40ms);
    const json st = c.ask({{"type", "feel2d.state"}});
    EXPECT_EQ(st["mode"], mode);
    EXPECT_GE(st["samples"].get<int>(), 80);
    EXPECT_GT(st["blocks"].get<int>(), 0);
    EXPECT_GT(st["peak"].get<double>(), 0.0) << mode;
    EXPECT_TRUE(st["touching"].get<bool>());
  }
  // Leaving lifts the finger.
  s.disconnect(c.id);
  Client d(s);
  std::this_thread::sleep_for(60ms);
  EXPECT_FALSE(d.ask({{"type", "feel2d.state"}})["touching"].get<bool>());
}

namespace {

using texel::test_support::DisplayRig;

/// Records the display's drive value every 0.2 ms while it lives.
struct DriveRecorder {
  std::atomic<bool> stop{false};
  std::vector<std::uint16_t> values;
  std::thread thread;
  explicit DriveRecorder(texel::controller::HostHal& hal) {
    values.reserve(1 << 16);
    thread = std::thread([this, &hal] {
      while (!stop && values.size() < (1u << 16)) {
        values.push_back(hal.amplitude.load());
        std::this_thread::sleep_for(200us);
      }
    });
  }
  std::vector<std::uint16_t> finish() {
    stop = true;
    thread.join();
    return values;
  }
};

std::uint16_t largest(const std::vector<std::uint16_t>& v) { return v.empty() ? 0 : *std::max_element(v.begin(), v.end()); }

}  // namespace

TEST(Surface2DStudio, PadPlaysOnTheStudiosSerialDisplayAndHandsItOver) {
  DisplayRig rig;
  ServiceOptions o;
  o.backend = "serial:" + rig.path;
  Service s(o);
  Client c(s);
  const json one_d = {
      {"format", "texel-document"},
      {"version", 1},
      {"device", "tpad"},
      {"texture",
       {{"kind", "texel"}, {"central_pitch_db", 10}, {"irregularity_db", -5}, {"texel_length_mm", 0.25}, {"seed", 1}}}};
  const json sel1 = c.ask({{"type", "feel.select"}, {"document", one_d}});
  ASSERT_EQ(sel1["type"], "feel.selected") << sel1.dump();
  ASSERT_EQ(c.ask({{"type", "feel2d.select"}, {"document", surface_document()}, {"mode", "bitmap"}})["type"], "feel2d.selected");
  json st = c.ask({{"type", "feel2d.state"}});
  EXPECT_NE(st["device"].get<std::string>().find("serial"), std::string::npos) << st.dump();
  EXPECT_FALSE(st["holds_device"].get<bool>());  // the Presenter has it until the pad is touched

  // A stroke on the pad: the display receives the 2-D player's drive values.
  DriveRecorder during(*rig.hal);
  for (int i = 0; i < 120; ++i) {
    const json a = c.ask({{"type", "feel2d.move"}, {"seq", i}, {"x_mm", 5.0 + 0.25 * i}, {"y_mm", 15.0}, {"touch", true}});
    ASSERT_EQ(a["type"], "feel2d.ack") << a.dump();
    std::this_thread::sleep_for(1ms);
  }
  // Held still at the disc's centre (c = 1): a steady drive the hand-over must ramp down.
  for (int i = 0; i < 40; ++i) {
    c.ask({{"type", "feel2d.move"}, {"seq", 200 + i}, {"x_mm", 20.0}, {"y_mm", 15.0}, {"touch", true}});
    std::this_thread::sleep_for(1ms);
  }
  std::this_thread::sleep_for(30ms);
  const auto stroke = during.finish();
  st = c.ask({{"type", "feel2d.state"}});
  EXPECT_TRUE(st["holds_device"].get<bool>()) << st.dump();
  EXPECT_NE(st["backend"].get<std::string>().find("serial"), std::string::npos) << st.dump();
  EXPECT_EQ(st["error"], "") << st.dump();
  EXPECT_GT(st["blocks"].get<int>(), 50);
  const std::uint16_t held = rig.hal->amplitude.load();
  EXPECT_GT(largest(stroke), 0) << "the display never received a drive value from the pad";
  EXPECT_GT(held, 65535 / 10) << "the finger held on the disc drives the display";

  // The Feel-it strip is touched: the pad's finger ramps out, the Presenter takes the display back.
  rig.start_log();
  DriveRecorder handover(*rig.hal);
  for (int i = 0; i < 150; ++i) {
    const json a = c.ask({{"type", "feel.move"}, {"seq", i}, {"t_ms", i}, {"x_mm", 20.0 + 0.1 * i}, {"touch", true}});
    ASSERT_EQ(a["type"], "feel.ack") << a.dump();
    std::this_thread::sleep_for(1ms);
  }
  std::this_thread::sleep_for(30ms);
  const auto back = handover.finish();
  const auto ticks = rig.take_log();
  // Up to the moment the display rests (between the two players), every drive value the host
  // sent is a step down a ramp: no fall of more than 60 % of the held drive from one frame to
  // the next. (Frames a loaded machine delivered together count as that many steps.)
  const auto rest = std::find_if(ticks.begin(), ticks.end(), [](const auto& t) { return t.amplitude == 0; });
  ASSERT_NE(rest, ticks.end()) << "the display never came to rest between the two players";
  double steepest = 0.0;
  for (auto t = ticks.begin() + 1; t <= rest; ++t) {
    const double fall = static_cast<double>(t[-1].amplitude) - static_cast<double>(t->amplitude);
    const double frames = std::max<double>(1.0, static_cast<double>(t->drive_values - t[-1].drive_values));
    steepest = std::max(steepest, fall / frames);
  }
  EXPECT_LT(steepest, held * 0.6) << "a click: the drive fell from " << held << " at once";
  EXPECT_GT(largest(back), 0) << "the 1-D strip drives the display again";
  st = c.ask({{"type", "feel2d.state"}});
  EXPECT_FALSE(st["holds_device"].get<bool>());
  const json fs = c.ask({{"type", "feel.state"}});
  EXPECT_NE(fs["backend"].get<std::string>().find("serial"), std::string::npos) << fs.dump();
  EXPECT_EQ(fs["error"], "") << fs.dump();
  c.ask({{"type", "feel.move"}, {"seq", 999}, {"t_ms", 150}, {"x_mm", 35.0}, {"touch", false}});

  // And the pad takes it once more (the display says HELLO again).
  for (int i = 0; i < 30; ++i) {
    c.ask({{"type", "feel2d.move"}, {"seq", 300 + i}, {"x_mm", 20.0}, {"y_mm", 15.0}, {"touch", true}});
    std::this_thread::sleep_for(1ms);
  }
  std::this_thread::sleep_for(30ms);
  st = c.ask({{"type", "feel2d.state"}});
  EXPECT_TRUE(st["holds_device"].get<bool>()) << st.dump();
  EXPECT_GT(rig.hal->amplitude.load(), 65535 / 10);
  EXPECT_EQ(rig.ctl->status().frames_bad, 0u);
}

TEST(Surface2DStudio, HearItGetsTheBitmapAtTheDevicesResolution) {
  Service s(ServiceOptions{});
  Client c(s);
  const json doc = surface_document();
  const json r = c.ask({{"type", "feel2d.raster"}, {"document", doc}});
  ASSERT_EQ(r["type"], "feel2d.raster") << r.dump().substr(0, 300);
  EXPECT_TRUE(r["whole"].get<bool>());
  EXPECT_EQ(r["width_px"], 400);
  EXPECT_EQ(r["height_px"], 300);
  EXPECT_EQ(r["depth_bits"], 8);
  const auto px = texel::studio::detail::base64_decode(r["amplitude"].get<std::string>()).value();
  ASSERT_EQ(px.size(), 400u * 300u);
  // Exactly the pixels the device's bitmap file holds (darker = more friction: level = pixel).
  const texel::Surface2D surface = texel::prepare_surface2d(texel::parse_document(doc.dump(), "doc"));
  std::vector<std::uint16_t> file(400u * 300u);
  texel::render_pixel_rows(surface, 0, 300, 0, file);
  int differ = 0;
  for (std::size_t i = 0; i < px.size(); ++i) differ += px[i] != file[i];
  EXPECT_LE(differ, 2);  // float rounding at a level's edge
  // The same raster as a library call: the device's pitch, quantised levels.
  const texel::Raster2D raster = texel::studio::device_raster(surface);
  EXPECT_EQ(raster.width, 400);
  EXPECT_DOUBLE_EQ(raster.pitch.value(), 0.1);
  EXPECT_NEAR(raster.values[1234] * 255.0, std::round(raster.values[1234] * 255.0), 1e-3);
}

TEST(Surface2DStudio, ADisplaysOwnFingerDrivesThePadsPlayerAndThePadShowsIt) {
  // The finger circles (8 mm about the disc's centre, (20, 15) mm) twice a second, lifted for a tenth of each turn.
  texel::controller::HostHal* hal = nullptr;
  DisplayRig rig([&hal](std::int32_t& x, std::int32_t& y, bool& touch) {
    const double t = hal ? hal->micros() * 1e-6 : 0.0;
    const double turn = 2.0 * t - std::floor(2.0 * t);
    x = static_cast<std::int32_t>(std::lround((20.0 + 8.0 * std::cos(2 * M_PI * turn)) * 1e6));
    y = static_cast<std::int32_t>(std::lround((15.0 + 8.0 * std::sin(2 * M_PI * turn)) * 1e6));
    touch = turn < 0.9;
    return true;
  });
  hal = rig.hal.get();
  ServiceOptions o;
  o.backend = "serial:" + rig.path;
  Service s(o);
  Client c(s);
  ASSERT_EQ(c.ask({{"type", "feel2d.select"}, {"document", surface_document()}, {"mode", "bitmap"}})["type"], "feel2d.selected");
  EXPECT_EQ(c.ask({{"type", "feel2d.state"}})["finger"], "pad");
  // A touch on the pad gives the 2-D player the display; from then on the display's finger drives it.
  ASSERT_EQ(c.ask({{"type", "feel2d.move"}, {"seq", 1}, {"x_mm", 2}, {"y_mm", 2}, {"touch", true}})["type"], "feel2d.ack");
  DriveRecorder drive(*rig.hal);
  for (int i = 2; i < 20; ++i)
    c.ask({{"type", "feel2d.move"}, {"seq", i}, {"x_mm", 2}, {"y_mm", 2}, {"touch", true}});  // shown, not played
  // The display reports at about 1 kHz: a few hundred of them, whatever the machine's load
  // (each state carries the trail since the last one).
  json st;
  std::vector<json> trail;
  for (int i = 0; i < 200; ++i) {
    std::this_thread::sleep_for(50ms);
    st = c.ask({{"type", "feel2d.state"}});
    for (const json& p : st["trail"]) trail.push_back(p);
    if (st.value("reports", 0) > 300 && trail.size() > 200) break;
  }
  const auto values = drive.finish();
  EXPECT_EQ(st["finger"], "display") << st.dump().substr(0, 400);
  EXPECT_TRUE(st["holds_device"].get<bool>());
  EXPECT_EQ(st["error"], "");
  EXPECT_GT(st["reports"].get<int>(), 300) << "reports from the display";
  ASSERT_GT(trail.size(), 200u);
  int on_circle = 0;
  for (const json& p : trail)
    on_circle += std::abs(std::hypot(p[0].get<double>() - 20.0, p[1].get<double>() - 15.0) - 8.0) < 0.01;
  EXPECT_EQ(on_circle, static_cast<int>(trail.size())) << "the pad is shown the display's finger";
  EXPECT_GT(largest(values), 65535 / 20) << "the display's finger on the map drives the display";
  EXPECT_EQ(st["samples"].get<int>(), 0) << "the pad's own samples are not played meanwhile";
  // The Feel-it strip takes the display back: it stops reporting, and the pad's pointer is the finger again.
  c.ask({{"type", "feel.move"}, {"seq", 1}, {"t_ms", 0}, {"x_mm", 10}, {"touch", true}});
  const json back = c.ask({{"type", "feel2d.state"}});
  EXPECT_EQ(back["finger"], "pad");
  EXPECT_FALSE(back["holds_device"].get<bool>());
  EXPECT_EQ(c.ask({{"type", "feel.state"}})["error"], "");
}

// The presentation follows the study's device (studio.md "Actuator arrays"):
// a lab starts the studio once; starting the distributed-irregularity study
// (pad-4, four actuators) re-opens the output with four channels, its
// stimuli play, a one-channel study afterwards gets one channel back, and a
// four-actuator document felt on the strip takes four again. An output that
// cannot open them (a serial display drives one plate) refuses the start in
// one line and stores nothing.
TEST(Surface2DStudio, AStudyOnAnActuatorArrayOpensTheOutputWithItsChannels) {
  texel::test_support::TempDir dir("studio-channels");
  ServiceOptions o;
  o.db_path = dir.at("s.db");
  o.protocols_dir = std::string(TEXEL_TEST_SOURCE_DIR) + "/examples/protocols";
  {
    Service s(o);
    Client c(s);
    const auto backend = [&] { return c.ask({{"type", "feel.state"}})["backend"].get<std::string>(); };
    EXPECT_EQ(backend().find("4 channels"), std::string::npos) << backend();
    const json started = c.ask({{"type", "experiment.start"}, {"protocol", "distributed-irregularity"}, {"participant", "A1"}});
    ASSERT_EQ(started["type"], "experiment.started") << started.dump();
    EXPECT_NE(backend().find("4 channels"), std::string::npos) << backend();
    const json q = c.ask({{"type", "experiment.current"}});
    const int t = q["question"]["trial"];
    for (int i = 0; i < 3; ++i)
      EXPECT_EQ(c.ask({{"type", "experiment.select"}, {"trial", t}, {"stimulus", i}})["type"], "experiment.selected");
    EXPECT_EQ(c.ask({{"type", "feel.state"}})["error"], "");
    EXPECT_EQ(c.ask({{"type", "experiment.stop"}})["type"], "experiment.idle");
    ASSERT_EQ(c.ask({{"type", "experiment.start"}, {"protocol", "texel-length"}, {"participant", "A1"}})["type"],
              "experiment.started");
    EXPECT_EQ(backend().find("4 channels"), std::string::npos) << backend();
    EXPECT_EQ(c.ask({{"type", "experiment.stop"}})["type"], "experiment.idle");
    const json array_document = {
        {"format", "texel-document"},
        {"version", 6},
        {"device", "pad-4"},
        {"texture", {{"kind", "texel"}, {"central_pitch_db", 6}, {"irregularity_db", 1}, {"texel_length_mm", 1}, {"seed", 3}}},
        {"playback", {{"mode", "simultaneous"}}}};
    EXPECT_EQ(c.ask({{"type", "feel.select"}, {"document", array_document}})["type"], "feel.selected");
    EXPECT_NE(backend().find("4 channels"), std::string::npos) << backend();
  }
  DisplayRig rig;
  o.backend = "serial:" + rig.path;
  o.db_path = dir.at("serial.db");
  Service s(o);
  Client c(s);
  const json refused = c.ask({{"type", "experiment.start"}, {"protocol", "distributed-irregularity"}, {"participant", "A2"}});
  ASSERT_EQ(refused["type"], "error") << refused.dump();
  EXPECT_NE(refused["message"].get<std::string>().find(
                "experiment.start: protocol distributed-irregularity: it plays on 4 channels and the output serial:"),
            std::string::npos)
      << refused.dump();
  EXPECT_EQ(c.ask({{"type", "experiment.list"}})["sessions"].size(), 0u);
  EXPECT_NE(c.ask({{"type", "feel.state"}})["backend"].get<std::string>().find("serial"), std::string::npos);
}
