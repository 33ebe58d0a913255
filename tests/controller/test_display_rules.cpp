// The display's rules, stepped on a simulated clock (no pty, no threads, no
// timing): only host frames refresh the watchdog, a display playing its own
// map rests while the finger is lifted, a lost link rests the output, the
// limits it announces are the limits it keeps, STATUS revision 1.2, error
// clearing, MAP_BEGIN during an upload, and the deliberate faults that
// `texel display-check` must catch.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "texel/controller/controller.hpp"
#include "texel/serial_protocol.hpp"

using namespace texel;
namespace ser = texel::serial;

namespace {

struct Reply {
  ser::Type type;
  std::uint8_t seq;
  std::vector<std::uint8_t> payload;
};

// A display's hardware with a hand-turned clock and a scripted link.
class FakeHal final : public controller::Hal {
 public:
  std::uint32_t now = 5000000;
  bool down = false;
  bool has_sensor = false;
  std::int32_t sensor_x = 0;
  bool sensor_touch = false;
  std::uint16_t amplitude = 0;

  std::uint32_t micros() override { return now; }
  int serial_read(std::uint8_t* buf, int max) override {
    if (down) return -1;
    const auto n = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(max), in_.size() - in_pos_));
    std::copy_n(in_.begin() + static_cast<std::ptrdiff_t>(in_pos_), n, buf);
    in_pos_ += static_cast<std::size_t>(n);
    return n;
  }
  bool serial_write(const std::uint8_t* buf, int n) override {
    if (down) return false;
    out_.insert(out_.end(), buf, buf + n);
    return true;
  }
  bool read_position(std::int32_t& x, bool& touch) override {
    if (!has_sensor) return false;
    x = sensor_x;
    touch = sensor_touch;
    return true;
  }
  void write_amplitude(std::uint16_t a) override { amplitude = a; }
  void idle_until(std::uint32_t) override {}

  void frame(ser::Type type, std::vector<std::uint8_t> payload) {
    std::uint8_t f[ser::max_frame];
    const std::size_t n = ser::encode_frame(type, seq_++, payload.data(), payload.size(), f);
    in_.insert(in_.end(), f, f + n);
  }
  // The frames the display sent since the last call.
  std::vector<Reply> replies() {
    std::vector<Reply> got;
    decoder_.feed(
        out_.data(), out_.size(),
        [&](const ser::Frame& f) {
          got.push_back({f.type, f.seq, std::vector<std::uint8_t>(f.payload, f.payload + f.length)});
        },
        [](ser::ErrorCode) {});
    out_.clear();
    return got;
  }

 private:
  std::vector<std::uint8_t> in_, out_;
  std::size_t in_pos_ = 0;
  std::uint8_t seq_ = 0;
  ser::Decoder decoder_;
};

using Ctl = controller::Controller<1024, 2>;

// Runs the display for `us` microseconds of its clock, polling every 20 µs.
void run_for(Ctl& c, FakeHal& hal, std::uint32_t us) {
  for (std::uint32_t t = 0; t < us; t += 20) {
    hal.now += 20;
    c.poll();
  }
}

std::vector<std::uint8_t> u32le(std::uint32_t v) {
  return {std::uint8_t(v), std::uint8_t(v >> 8), std::uint8_t(v >> 16), std::uint8_t(v >> 24)};
}

std::vector<std::uint8_t> cat(std::initializer_list<std::vector<std::uint8_t>> parts) {
  std::vector<std::uint8_t> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// Uploads `values` into `slot` (100 µm spacing, origin 0) in one MAP_DATA.
void upload(FakeHal& hal, std::uint8_t slot, const std::vector<std::uint16_t>& values, bool bad_crc = false) {
  hal.frame(ser::Type::map_begin, cat({{slot, 0}, u32le(static_cast<std::uint32_t>(values.size())), u32le(100000), u32le(0)}));
  std::vector<std::uint8_t> data = cat({{slot}, u32le(0)});
  for (std::uint16_t v : values) data.insert(data.end(), {std::uint8_t(v), std::uint8_t(v >> 8)});
  hal.frame(ser::Type::map_data, data);
  const std::uint32_t crc = ser::crc32(data.data() + 5, data.size() - 5);
  hal.frame(ser::Type::map_end, cat({{slot}, u32le(bad_crc ? ~crc : crc)}));
}

std::vector<std::uint16_t> ramp(std::size_t n) {
  std::vector<std::uint16_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint16_t>(1000 + 50 * i);
  return v;
}

void expect_acks(FakeHal& hal, std::size_t n) {
  const auto r = hal.replies();
  ASSERT_EQ(r.size(), n);
  for (const Reply& x : r) EXPECT_EQ(x.type, ser::Type::ack) << int(x.payload.size() > 1 ? x.payload[1] : 0);
}

Reply only_reply(FakeHal& hal) {
  auto r = hal.replies();
  EXPECT_EQ(r.size(), 1u);
  return r.empty() ? Reply{ser::Type::ack, 0, {}} : r.front();
}

}  // namespace

TEST(DisplayRules, ASensorReadingNeverKeepsAStaleDriveGoing) {
  FakeHal hal;
  hal.has_sensor = true;
  hal.sensor_x = 5000000;  // 5 mm, touching the whole time
  hal.sensor_touch = true;
  Ctl c(hal, controller::Info{});
  hal.frame(ser::Type::drive, {0x40, 0x9C});  // 40000
  run_for(c, hal, 1000);
  EXPECT_EQ(hal.amplitude, 40000);
  run_for(c, hal, 198000);  // 199 ms after the DRIVE: still driven
  EXPECT_EQ(hal.amplitude, 40000);
  run_for(c, hal, 2000);  // past 200 ms: at rest, although the finger is sensed
  EXPECT_EQ(hal.amplitude, 0);
  EXPECT_TRUE(c.status().stale);
  hal.frame(ser::Type::drive, {0x10, 0x27});  // a new host frame drives again
  run_for(c, hal, 200);
  EXPECT_EQ(hal.amplitude, 10000);
}

TEST(DisplayRules, ADisplayPlayingItsOwnMapFollowsTheFingerAndRestsWhenItLifts) {
  FakeHal hal;
  hal.has_sensor = true;
  Ctl c(hal, controller::Info{});
  const auto map = ramp(100);
  upload(hal, 0, map);
  hal.frame(ser::Type::select, {0});
  run_for(c, hal, 200);
  expect_acks(hal, 4);
  for (std::int32_t x_um : {0, 1230, 5000, 9900}) {
    hal.sensor_x = x_um * 1000;
    hal.sensor_touch = true;
    run_for(c, hal, 300000);  // no host stream at all: the display plays on its own
    EXPECT_EQ(hal.amplitude, map[static_cast<std::size_t>((x_um + 50) / 100)]) << x_um;
    hal.sensor_touch = false;
    run_for(c, hal, 200);
    EXPECT_EQ(hal.amplitude, 0) << "lifted at " << x_um;
  }
}

TEST(DisplayRules, StreamedPositionsThatStopArrivingRestTheOutput) {
  FakeHal hal;
  Ctl c(hal, controller::Info{});
  const auto map = ramp(100);
  upload(hal, 1, map);
  hal.frame(ser::Type::select, {1});
  hal.frame(ser::Type::position, cat({u32le(2000000), {1}}));
  run_for(c, hal, 1000);
  EXPECT_EQ(hal.amplitude, map[20]);
  run_for(c, hal, 198000);  // 199 ms after the POSITION
  EXPECT_EQ(hal.amplitude, map[20]);
  run_for(c, hal, 2000);
  EXPECT_EQ(hal.amplitude, 0);
}

TEST(DisplayRules, ALostLinkRestsTheOutputAndKeepsTheMaps) {
  FakeHal hal;
  hal.has_sensor = true;
  hal.sensor_x = 3000000;
  hal.sensor_touch = true;
  Ctl c(hal, controller::Info{});
  upload(hal, 0, ramp(100));
  hal.frame(ser::Type::select, {0});
  run_for(c, hal, 500);
  EXPECT_NE(hal.amplitude, 0);
  hal.down = true;  // unplugged
  run_for(c, hal, 500);
  EXPECT_EQ(hal.amplitude, 0);
  EXPECT_EQ(c.status().selected, ser::no_map);
  EXPECT_EQ(c.status().link_errors, 1u);
  EXPECT_EQ(c.map_samples(0), 100u);
  hal.down = false;  // a host comes back and selects again
  hal.frame(ser::Type::select, {0});
  run_for(c, hal, 500);
  EXPECT_EQ(hal.amplitude, ramp(100)[30]);
}

TEST(DisplayRules, TheLimitsAnnouncedAreTheLimitsKept) {
  FakeHal hal;
  controller::Info info;
  info.max_payload = 256;
  info.slots = 1;
  info.max_samples = 500;
  Ctl c(hal, info);
  hal.frame(ser::Type::hello, {1});
  run_for(c, hal, 100);
  Reply r = only_reply(hal);
  ASSERT_EQ(r.type, ser::Type::hello_reply);
  EXPECT_EQ(r.payload[1], 1);                               // slots
  EXPECT_EQ(ser::get_u32(r.payload.data() + 2), 500u);      // max_samples
  EXPECT_EQ(ser::get_u32(r.payload.data() + 6), 8333000u);  // refresh in millihertz
  EXPECT_EQ(ser::get_u16(r.payload.data() + 10), 256);      // max_payload
  // A payload longer than announced: NACK bad_length, detail = max_payload.
  hal.frame(ser::Type::map_begin, cat({{0, 0}, u32le(400), u32le(100000), u32le(0)}));
  hal.frame(ser::Type::map_data, cat({{0}, u32le(0), std::vector<std::uint8_t>(2 * 130, 7)}));  // 265 bytes
  run_for(c, hal, 100);
  auto rs = hal.replies();
  ASSERT_EQ(rs.size(), 2u);
  EXPECT_EQ(rs[0].type, ser::Type::ack);
  ASSERT_EQ(rs[1].type, ser::Type::nack);
  EXPECT_EQ(rs[1].payload[1], static_cast<std::uint8_t>(ser::ErrorCode::bad_length));
  EXPECT_EQ(ser::get_u32(rs[1].payload.data() + 2), 256u);
  // The second slot and the 501st sample do not exist.
  hal.frame(ser::Type::map_begin, cat({{1, 0}, u32le(10), u32le(100000), u32le(0)}));
  hal.frame(ser::Type::map_begin, cat({{0, 0}, u32le(501), u32le(100000), u32le(0)}));
  run_for(c, hal, 100);
  rs = hal.replies();
  ASSERT_EQ(rs.size(), 2u);
  EXPECT_EQ(rs[0].payload[1], static_cast<std::uint8_t>(ser::ErrorCode::unknown_map));
  EXPECT_EQ(ser::get_u32(rs[0].payload.data() + 2), 1u);
  EXPECT_EQ(rs[1].payload[1], static_cast<std::uint8_t>(ser::ErrorCode::oversize_map));
  EXPECT_EQ(ser::get_u32(rs[1].payload.data() + 2), 500u);
}

TEST(DisplayRules, StatusRevision12AppendsLinkErrorsAndFlagsAndClearsTheLastError) {
  FakeHal hal;
  hal.has_sensor = true;
  Ctl c(hal, controller::Info{});
  hal.frame(ser::Type::select, {0});  // empty slot: NACK unknown_map
  hal.frame(ser::Type::status_request, {});
  hal.frame(ser::Type::status_request, {});
  run_for(c, hal, 100);
  const auto rs = hal.replies();
  ASSERT_EQ(rs.size(), 3u);
  ASSERT_EQ(rs[1].type, ser::Type::status);
  ASSERT_EQ(rs[1].payload.size(), ser::status_payload);
  EXPECT_EQ(rs[1].payload[17], static_cast<std::uint8_t>(ser::ErrorCode::unknown_map));
  EXPECT_EQ(ser::get_u32(rs[1].payload.data() + 26), 0u);  // link_errors
  EXPECT_EQ(rs[1].payload[30] & ser::status_flag_sensor, ser::status_flag_sensor);
  EXPECT_EQ(rs[2].payload[17], 0) << "reported once, then cleared";
}

TEST(DisplayRules, MapBeginDuringAnUploadAbandonsItAndDataPastTheEndIsRefused) {
  FakeHal hal;
  Ctl c(hal, controller::Info{});
  hal.frame(ser::Type::map_begin, cat({{0, 0}, u32le(10), u32le(100000), u32le(0)}));
  hal.frame(ser::Type::map_data, cat({{0}, u32le(0), std::vector<std::uint8_t>(10, 1)}));  // 5 samples
  upload(hal, 0, ramp(4));  // a new MAP_BEGIN: the first upload is gone
  hal.frame(ser::Type::map_begin, cat({{1, 0}, u32le(2), u32le(100000), u32le(0)}));
  hal.frame(ser::Type::map_data, cat({{1}, u32le(0), std::vector<std::uint8_t>(6, 1)}));  // 3 samples into 2
  run_for(c, hal, 100);
  const auto rs = hal.replies();
  ASSERT_EQ(rs.size(), 7u);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(rs[static_cast<std::size_t>(i)].type, ser::Type::ack) << i;
  ASSERT_EQ(rs[6].type, ser::Type::nack);
  EXPECT_EQ(rs[6].payload[1], static_cast<std::uint8_t>(ser::ErrorCode::oversize_map));
  EXPECT_EQ(ser::get_u32(rs[6].payload.data() + 2), 2u);
  EXPECT_EQ(c.map_samples(0), 4u);
  EXPECT_EQ(c.map_value(0, 3), ramp(4)[3]);
}

TEST(DisplayRules, TheDeliberateFaultsMisbehaveAsNamed) {
  {
    FakeHal hal;
    controller::Info info;
    info.faults = controller::fault_wrong_crc;
    Ctl c(hal, info);
    upload(hal, 0, ramp(8), /*bad_crc=*/true);
    run_for(c, hal, 100);
    expect_acks(hal, 3);  // a correct display answers map_checksum
    EXPECT_EQ(c.map_samples(0), 8u);
  }
  {
    FakeHal hal;
    controller::Info info;
    info.faults = controller::fault_ignore_watchdog;
    Ctl c(hal, info);
    hal.frame(ser::Type::drive, {0x40, 0x9C});
    run_for(c, hal, 500000);
    EXPECT_EQ(hal.amplitude, 40000);
  }
  {
    FakeHal hal;
    hal.has_sensor = true;
    controller::Info info;
    info.faults = controller::fault_drop_reports;
    Ctl c(hal, info);
    hal.frame(ser::Type::reports, u32le(1000));
    run_for(c, hal, 20000);
    auto rs = hal.replies();
    std::vector<std::uint8_t> seqs;
    for (const Reply& r : rs)
      if (r.type == ser::Type::finger) seqs.push_back(r.seq);
    ASSERT_GE(seqs.size(), 10u);
    bool gap = false;
    for (std::size_t i = 1; i < seqs.size(); ++i) gap |= seqs[i] != static_cast<std::uint8_t>(seqs[i - 1] + 1);
    EXPECT_TRUE(gap);
  }
}

TEST(DisplayRules, AnArmedHostWatchdogRestsADisplayPlayingItsOwnMapWhenTheHostFallsSilent) {
  FakeHal hal;
  hal.has_sensor = true;
  hal.sensor_x = 2000000;
  hal.sensor_touch = true;
  Ctl c(hal, controller::Info{});
  upload(hal, 0, ramp(100));
  hal.frame(ser::Type::select, {0});
  hal.frame(ser::Type::host_watchdog, u32le(100));
  run_for(c, hal, 200);
  expect_acks(hal, 5);
  for (int k = 0; k < 10; ++k) {  // fed every 80 ms: keeps playing
    run_for(c, hal, 80000);
    hal.frame(ser::Type::keepalive, {});
  }
  run_for(c, hal, 1000);
  EXPECT_EQ(hal.amplitude, ramp(100)[20]);
  EXPECT_EQ(c.status().host_timeouts, 0u);
  run_for(c, hal, 99000);  // 100 ms of silence
  EXPECT_EQ(hal.amplitude, ramp(100)[20]);
  run_for(c, hal, 2000);  // past it: at rest, selection cleared, disarmed
  EXPECT_EQ(hal.amplitude, 0);
  EXPECT_EQ(c.status().selected, ser::no_map);
  EXPECT_EQ(c.status().host_timeouts, 1u);
  EXPECT_EQ(c.status().host_timeout_us, 0u);
  // Out of range: refused with the shortest allowed.
  hal.frame(ser::Type::host_watchdog, u32le(5));
  run_for(c, hal, 100);
  const Reply r = only_reply(hal);
  ASSERT_EQ(r.type, ser::Type::nack);
  EXPECT_EQ(r.payload[1], static_cast<std::uint8_t>(ser::ErrorCode::bad_value));
  EXPECT_EQ(ser::get_u32(r.payload.data() + 2), 20u);
}
