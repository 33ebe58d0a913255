// The one signal loader (texel/signal.hpp): every format reads the same map
// to the same samples; every class of bad input is refused with an error
// that names the option field (FieldError) or the file (FormatError).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "../support/wav.hpp"
#include "texel/bitstream.hpp"
#include "texel/codec.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/matfile.hpp"
#include "texel/signal.hpp"
#include "texel/surface.hpp"

namespace fs = std::filesystem;
using namespace texel;

namespace {

using test_support::wav_bytes;

std::span<const std::byte> as_span(const std::string& s) { return std::as_bytes(std::span(s.data(), s.size())); }

class SignalLoader : public ::testing::Test {
 protected:
  texel::test_support::TempDir tmp{"texel-signal"};
  const fs::path& dir = tmp.path;
  DeviceProfile tpad = load_device("tpad");
  Document doc;
  std::vector<double> map;

  void SetUp() override {
    TexelSpec spec;
    spec.seed = 9;
    doc = make_document(tpad, spec);
    map = prepare_surface(doc).render();
  }

  std::string put(const std::string& name, const std::string& bytes) const {
    const std::string p = (dir / name).string();
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  [[nodiscard]] std::vector<double> positions() const {
    std::vector<double> x(map.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i) * tpad.spacing.value();
    return x;
  }
  /// A sine of `frames` frames in channel 0 and silence in the others.
  static std::vector<std::int16_t> sine_frames(unsigned channels, std::size_t frames) {
    std::vector<std::int16_t> v(frames * channels, 0);
    for (std::size_t i = 0; i < frames; ++i) v[i * channels] = static_cast<std::int16_t>(16000 * std::sin(0.3 * i));
    return v;
  }
};

/// The field a FieldError names, or what else was thrown.
template <class F>
std::string field_of(F&& f) {
  try {
    f();
  } catch (const FieldError& e) {
    return e.field();
  } catch (const std::exception& e) {
    return std::string("not a FieldError: ") + e.what();
  }
  return "(no error)";
}

using texel::test_support::message_of;

}  // namespace

TEST_F(SignalLoader, EveryMapFormatReadsTheSameSamples) {
  std::vector<std::byte> native(map.size() * bytes_per_sample(tpad.format));
  encode_samples(tpad.format, map, native);
  const std::string bin = put("m.bin", std::string(reinterpret_cast<const char*>(native.data()), native.size()));
  const std::string npy = put("m.npy", npy_bytes(map));
  const std::string csv = put("m.csv", csv_columns("position_mm", "amplitude", positions(), map));
  const std::string json = put("m.texel.json", document_json(doc));
  const std::string mat = (dir / "m.mat").string();
  mat::write_mat(mat, {{"amplitude", mat::Matrix::column(map)}, {"spacing_mm", mat::Matrix::scalar(tpad.spacing.value())}});

  SignalOptions o;
  o.device = tpad;
  const Signal from_doc = load_signal(json);
  EXPECT_EQ(from_doc.samples, map);
  EXPECT_EQ(from_doc.format, SignalFormat::document);
  for (const std::string& path : {npy, csv, mat}) {
    const Signal s = load_signal(path, o);
    EXPECT_EQ(s.samples, map) << path;
    EXPECT_NEAR(s.spacing.value(), tpad.spacing.value(), 1e-12) << path;
    EXPECT_EQ(s.origin.value(), 0.0) << path;
    EXPECT_FALSE(s.scaled) << path;
  }
  const Signal b = load_signal(bin, o);
  ASSERT_EQ(b.samples.size(), map.size());
  for (std::size_t i = 0; i < map.size(); ++i) ASSERT_NEAR(b.samples[i], map[i], 0.5 / 65535) << i;
  EXPECT_EQ(b.format, SignalFormat::device_map);

  // The same bytes from memory read the same (what fuzzers and the studio call).
  EXPECT_EQ(decode_signal(as_span(read_file(csv)), SignalFormat::csv, o, "mem.csv").samples, map);
  EXPECT_EQ(decode_signal(as_span(read_file(npy)), SignalFormat::npy, o, "mem.npy").samples, map);
}

TEST_F(SignalLoader, BitstreamsDecodeThroughTheCodecOnTheGivenDevice) {
  const std::vector<std::byte> bytes = codec::write_bitstream(codec::from_spec(doc.regions.front().texel, tpad.length()));
  const std::string path = put("m.texel", std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  EXPECT_EQ(field_of([&] { codec::load_signal(path); }), "device");
  SignalOptions o;
  o.device = tpad;
  const Signal s = codec::load_signal(path, o);
  EXPECT_EQ(s.format, SignalFormat::bitstream);
  EXPECT_EQ(s.samples.size(), static_cast<std::size_t>(tpad.samples));
  // texel::load_signal alone does not decode bitstreams; it says where to go.
  EXPECT_THROW_MSG(load_signal(path, o), InvalidArgument, "codec::load_signal");
}

TEST_F(SignalLoader, TimeRecordingsBecomePositionsAtTheSwipeSpeed) {
  const std::string wav = put("r.wav", wav_bytes(1, 8000, sine_frames(1, 800)));
  EXPECT_EQ(field_of([&] { load_signal(wav); }), "swipe_speed");
  SignalOptions o;
  o.swipe_speed = MmPerSecond(100.0);
  const Signal s = load_signal(wav, o);
  EXPECT_EQ(s.format, SignalFormat::wav);
  ASSERT_TRUE(s.sample_rate.has_value());
  EXPECT_EQ(s.sample_rate->value(), 8000.0);
  EXPECT_DOUBLE_EQ(s.spacing.value(), 100.0 / 8000.0);
  EXPECT_EQ(s.samples.size(), 800u);
  EXPECT_TRUE(s.scaled);
  const auto [lo, hi] = std::minmax_element(s.samples.begin(), s.samples.end());
  EXPECT_TRUE(std::fabs(*hi - 1.0) < 1e-12 || std::fabs(*lo) < 1e-12) << *lo << " … " << *hi;  // 0.5 ± 0.5·y/max|y|

  // A time/value CSV is the same recording.
  std::string csv = "time_s,value\n";
  const Recording rec = read_recording(wav);
  for (std::size_t i = 0; i < rec.samples.size(); ++i)
    csv += std::to_string(i / 8000.0) + "," + std::to_string(rec.samples[i]) + "\n";
  const Signal t = load_signal(put("r.csv", csv), o);
  EXPECT_NEAR(t.spacing.value(), s.spacing.value(), 1e-6);
  ASSERT_EQ(t.samples.size(), s.samples.size());
  for (std::size_t i = 0; i < s.samples.size(); ++i) ASSERT_NEAR(t.samples[i], s.samples[i], 1e-5);
  EXPECT_EQ(field_of([&] { load_signal(put("r2.csv", csv)); }), "swipe_speed");
}

TEST_F(SignalLoader, ChannelPolicyOfMultiChannelRecordings) {
  const std::string wav = put("st.wav", wav_bytes(2, 8000, sine_frames(2, 400)));
  SignalOptions o;
  o.swipe_speed = MmPerSecond(100.0);
  // Default: refused, naming the channel count.
  EXPECT_EQ(field_of([&] { load_signal(wav, o); }), "channel");
  EXPECT_THROW_MSG(load_signal(wav, o), FieldError, "2 channels");
  // select: the channel asked for (channel 1 is silent: nothing to scale).
  o.channels = ChannelPolicy::select;
  o.channel = 0;
  const Recording left = read_recording(wav, o);
  EXPECT_EQ(left.channels, 2u);
  EXPECT_NE(left.samples[1], 0.0);
  o.channel = 1;
  for (double v : read_recording(wav, o).samples) ASSERT_EQ(v, 0.0);
  o.channel = 2;
  EXPECT_EQ(field_of([&] { read_recording(wav, o); }), "channel");
  // mix: the mean of the channels.
  o.channels = ChannelPolicy::mix;
  const Recording mixed = read_recording(wav, o);
  for (std::size_t i = 0; i < mixed.samples.size(); ++i) ASSERT_DOUBLE_EQ(mixed.samples[i], left.samples[i] / 2);
  // From memory (libsndfile virtual I/O) as from the file.
  EXPECT_EQ(decode_recording(as_span(read_file(wav)), o, "mem.wav").samples, mixed.samples);
}

TEST_F(SignalLoader, SpacingPolicy) {
  const std::string csv = put("m.csv", csv_columns("position_mm", "amplitude", positions(), map));
  SignalOptions o;
  o.spacing = Millimetres(0.5);
  EXPECT_EQ(field_of([&] { load_signal(csv, o); }), "spacing");
  o.spacing = Millimetres(tpad.spacing.value() * 1.005);  // within the 1 % tolerance
  EXPECT_NO_THROW(load_signal(csv, o));
  o.spacing = Millimetres(-1.0);
  EXPECT_EQ(field_of([&] { load_signal(csv, o); }), "spacing");
  // A .npy carries no grid: device or spacing.
  const std::string npy = put("m.npy", npy_bytes(map));
  EXPECT_EQ(field_of([&] { load_signal(npy); }), "spacing");
  o.spacing = Millimetres(0.01);
  EXPECT_DOUBLE_EQ(load_signal(npy, o).spacing.value(), 0.01);
  // A .bin needs its device.
  EXPECT_EQ(field_of([&] { load_signal(put("m.bin", std::string(200, '\0'))); }), "device");
  // Uneven positions are a format error naming the row.
  const std::string uneven = put("u.csv", "position_mm,amplitude\n0,0.1\n1,0.2\n2,0.3\n3.5,0.4\n4,0.5\n");
  EXPECT_THROW_MSG(load_signal(uneven), FormatError, "not uniformly sampled");
}

TEST_F(SignalLoader, ARegionKeepsOnlyTheSamplesInsideIt) {
  const std::string csv = put("m.csv", csv_columns("position_mm", "amplitude", positions(), map));
  SignalOptions o;
  o.region = SignalOptions::Region{"", Millimetres(10.0), Millimetres(20.0)};
  const Signal s = load_signal(csv, o);
  const auto first = static_cast<std::size_t>(std::ceil(10.0 / tpad.spacing.value()));
  EXPECT_NEAR(s.origin.value(), static_cast<double>(first) * tpad.spacing.value(), 1e-9);
  EXPECT_GE(s.origin.value(), 10.0);
  EXPECT_LT(s.origin.value() + (static_cast<double>(s.samples.size()) - 1) * tpad.spacing.value(), 20.0);
  EXPECT_EQ(s.samples.front(), map[first]);
  o.region = SignalOptions::Region{"", Millimetres(1000.0), Millimetres(2000.0)};
  EXPECT_EQ(field_of([&] { load_signal(csv, o); }), "region");
  o.region = SignalOptions::Region{"", Millimetres(20.0), Millimetres(10.0)};
  EXPECT_EQ(field_of([&] { load_signal(csv, o); }), "region");
  // A document's region by name.
  o.region = SignalOptions::Region{"nope", {}, {}};
  EXPECT_EQ(field_of([&] { load_signal(put("d.texel.json", document_json(doc)), o); }), "region");
  o.region = SignalOptions::Region{"0", {}, {}};
  EXPECT_EQ(load_signal(put("d2.texel.json", document_json(doc)), o).samples, map);
}

TEST_F(SignalLoader, DeclaredSizesAreBoundedBeforeAllocating) {
  SignalOptions o;
  o.device = tpad;
  o.max_samples = 100;
  EXPECT_EQ(field_of([&] { load_signal(put("m.npy", npy_bytes(map)), o); }), "max_samples");
  EXPECT_EQ(field_of([&] { load_signal(put("m.csv", csv_columns("x", "a", positions(), map)), o); }), "max_samples");
  std::vector<std::byte> native(map.size() * 2);
  encode_samples(tpad.format, map, native);
  EXPECT_EQ(field_of([&] { decode_signal(std::span<const std::byte>(native), SignalFormat::device_map, o, "mem.bin"); }),
            "max_samples");
  // A WAV that declares more frames than it holds is read to what it holds
  // by libsndfile; one that holds more than max_samples is refused before its buffer exists.
  o.swipe_speed = MmPerSecond(100.0);
  EXPECT_EQ(field_of([&] { load_signal(put("big.wav", wav_bytes(1, 8000, sine_frames(1, 1000))), o); }), "max_samples");
  o.max_samples = 1;
  EXPECT_EQ(field_of([&] { load_signal(put("m2.npy", npy_bytes(map)), o); }), "max_samples");
}

TEST_F(SignalLoader, RejectsBadInput) {
  EXPECT_THROW_MSG(load_signal(put("m.txt", "1,2\n")), InvalidArgument, "allowed: .bin");
  EXPECT_THROW(load_signal((dir / "missing.csv").string()), IoError);
  EXPECT_NE(message_of<FormatError>([&] { load_signal(put("e.csv", "position_mm,amplitude\n")); }).find("e.csv"),
            std::string::npos);
  EXPECT_THROW(load_signal(put("bad.csv", "0,0.1\n1,abc\n")), FormatError);
  EXPECT_THROW(load_signal(put("nan.csv", "0,0.1\n1,nan\n2,0.3\n")), FormatError);
  SignalOptions o;
  o.swipe_speed = MmPerSecond(100.0);
  EXPECT_THROW(load_signal(put("junk.wav", "RIFF....not a wave"), o), FormatError);
  EXPECT_THROW(decode_signal(as_span(std::string("x")), SignalFormat::mat, o, "mem.mat"), InvalidArgument);
  o.swipe_speed = MmPerSecond(0.0);
  EXPECT_EQ(field_of([&] { load_signal(put("z.wav", wav_bytes(1, 8000, sine_frames(1, 10))), o); }), "swipe_speed");
  // Maps outside [0, 1] are scaled to full range, and say so.
  const Signal raw = load_signal(put("raw.csv", "0,100\n1,300\n2,200\n"));
  EXPECT_TRUE(raw.scaled);
  EXPECT_DOUBLE_EQ(raw.samples[1], 1.0);
  EXPECT_DOUBLE_EQ(raw.samples[0], 0.0);
}

TEST(NumericCsv, OneReaderForSignalsTracesAndProfiles) {
  std::vector<std::vector<double>> rows;
  const std::string header =
      read_numeric_csv("\xEF\xBB\xBFt,x\r\n# c\r\n\r\n1, +2\t3\n4;5;6\n", "r.csv", 2, 3, "t,x[,y]",
                       [&](std::size_t, std::span<const double> v) { rows.emplace_back(v.begin(), v.end()); });
  EXPECT_EQ(header, "t,x");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0], (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(rows[1], (std::vector<double>{4, 5, 6}));
  auto none = [](std::size_t, std::span<const double>) {};
  EXPECT_NE(message_of<FormatError>([&] { read_numeric_csv("1,2,3,4\n", "r.csv", 2, 3, "t,x[,y]", none); }).find("r.csv:1"),
            std::string::npos);
  EXPECT_NE(message_of<FormatError>([&] { read_numeric_csv("1,2\n3\n", "r.csv", 2, 3, "t,x[,y]", none); }).find("r.csv:2"),
            std::string::npos);
  double v = 0;
  EXPECT_TRUE(parse_csv_number(" +1.5 ", v));
  EXPECT_EQ(v, 1.5);
  EXPECT_FALSE(parse_csv_number("1.5x", v));
  EXPECT_FALSE(parse_csv_number("", v));
}
