// The texel command line (apps/texel): issue #2's acceptance checks, and one
// test per class of bad input. A rejected command must exit with status 2,
// print exactly one line on stderr ("texel: ..." naming the problem), print
// nothing on stdout, and leave its working directory as it found it: no
// output file, no temporary file, a pre-existing output untouched.
//
// Each test runs the built binary (TEXEL_CLI_PATH) in a fresh directory.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "../support/wav.hpp"
#include "texel/io.hpp"

namespace fs = std::filesystem;

namespace {

struct Result {
  int status = -1;
  std::string out;
  std::string err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs `texel args...` in `cwd` with stdout/stderr captured (fork + exec: no
/// shell, so arguments need no quoting).
Result run_texel(const std::vector<std::string>& args, const fs::path& cwd) {
  const fs::path capture = fs::temp_directory_path() / ("texel-cli-capture-" + std::to_string(::getpid()));
  fs::create_directories(capture);
  const fs::path out_path = capture / "stdout";
  const fs::path err_path = capture / "stderr";
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0 || ::chdir(cwd.c_str()) != 0) ::_exit(127);
    std::vector<char*> argv;
    std::string exe = TEXEL_CLI_PATH;
    argv.push_back(exe.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(exe.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  Result r;
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out_path);
  r.err = slurp(err_path);
  fs::remove_all(capture);
  return r;
}

class Cli : public ::testing::Test {
 protected:
  texel::test_support::TempDir tmp{"texel-cli"};
  const fs::path& dir = tmp.path;

  Result run(const std::vector<std::string>& args) { return run_texel(args, dir); }

  void write(const std::string& name, const std::string& text) const { std::ofstream(dir / name, std::ios::binary) << text; }

  /// Every file and directory under `dir`, relative, with contents for files.
  [[nodiscard]] std::map<std::string, std::string> snapshot() const {
    std::map<std::string, std::string> s;
    for (const auto& e : fs::recursive_directory_iterator(dir))
      s[fs::relative(e.path(), dir).string()] = e.is_regular_file() ? slurp(e.path()) : std::string("<dir>");
    return s;
  }

  /// Runs a command that must be rejected as bad input.
  void expect_rejected(const std::vector<std::string>& args, const std::string& must_mention) {
    const auto before = snapshot();
    const Result r = run(args);
    std::string cmd = "texel";
    for (const auto& a : args) cmd += " " + a;
    EXPECT_EQ(r.status, 2) << cmd << "\nstderr: " << r.err;
    EXPECT_EQ(r.out, "") << cmd;
    ASSERT_FALSE(r.err.empty()) << cmd;
    EXPECT_EQ(r.err.rfind("texel: ", 0), 0u) << cmd << ": " << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << cmd << ": message must be exactly one line: " << r.err;
    EXPECT_NE(r.err.find(must_mention), std::string::npos) << cmd << ": expected '" << must_mention << "' in: " << r.err;
    EXPECT_EQ(snapshot(), before) << cmd << ": the directory changed (output or temporary file left behind)";
  }

  std::string valid_document() const {
    return R"({
  "format": "texel-document",
  "version": 1,
  "device": "tpad",
  "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 3}
})";
  }
};

std::vector<std::string> read_lines(const fs::path& p) {
  std::vector<std::string> lines;
  std::ifstream in(p);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

}  // namespace

// ---------------------------------------------------------------- acceptance

TEST_F(Cli, AcceptanceTpadFileIsDeterministicAndSeedDependent) {
  const std::vector<std::string> base = {"render", "--central-pitch", "10",  "--irregularity", "-5", "--texel-length",
                                         "0.25",   "--device",        "tpad"};
  auto with = [&](std::vector<std::string> extra) {
    auto a = base;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  ASSERT_EQ(run(with({"--seed", "7", "-o", "a.bin"})).status, 0);
  ASSERT_EQ(run(with({"--seed", "7", "-o", "again.bin"})).status, 0);
  ASSERT_EQ(run(with({"--seed", "8", "-o", "seed8.bin"})).status, 0);
  EXPECT_EQ(fs::file_size(dir / "a.bin"), 38400u);  // 19,200 × u16
  EXPECT_EQ(slurp(dir / "a.bin"), slurp(dir / "again.bin"));
  EXPECT_NE(slurp(dir / "a.bin"), slurp(dir / "seed8.bin"));
  EXPECT_EQ(fs::file_size(dir / "seed8.bin"), 38400u);
  // The document written for the same texture renders the same bytes.
  ASSERT_EQ(run(with({"--seed", "7", "-o", "a.texel.json"})).status, 0);
  ASSERT_EQ(run({"render", "a.texel.json", "-o", "from-doc.bin"}).status, 0);
  EXPECT_EQ(slurp(dir / "a.bin"), slurp(dir / "from-doc.bin"));
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"a.bin", "again.bin", "seed8.bin", "a.texel.json", "from-doc.bin"}));
}

TEST_F(Cli, AcceptanceGenericTexelStatisticsAndSignalFrequencies) {
  const Result r = run({"render", "--device", "generic", "--length", "2000", "--spacing", "0.005", "--texel-length", "1",
                        "--central-pitch", "6", "--irregularity", "3", "--texels", "t.csv", "-o", "s.csv"});
  ASSERT_EQ(r.status, 0) << r.err;

  // Per-texel frequencies: mean and SD within 3 % / 10 % of 10^0.6 and 10^0.3
  // cpm (the issue's tolerance; with 2000 texels the SEs are 1.1 % and 1.8 %).
  const auto rows = read_lines(dir / "t.csv");
  ASSERT_EQ(rows.size(), 2001u);
  EXPECT_EQ(rows[0], "index,start_mm,frequency_cpm,amplitude");
  std::vector<double> f;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    std::istringstream in(rows[k]);
    std::string idx, start, freq, amp;
    std::getline(in, idx, ',');
    std::getline(in, start, ',');
    std::getline(in, freq, ',');
    std::getline(in, amp, ',');
    ASSERT_EQ(std::stoul(idx), k - 1);
    ASSERT_DOUBLE_EQ(std::stod(start), static_cast<double>(k - 1));
    f.push_back(std::stod(freq));
  }
  double mean = 0.0;
  for (double v : f) mean += v;
  mean /= static_cast<double>(f.size());
  double s2 = 0.0;
  for (double v : f) s2 += (v - mean) * (v - mean);
  const double sd = std::sqrt(s2 / static_cast<double>(f.size() - 1));
  EXPECT_NEAR(mean / std::pow(10.0, 0.6), 1.0, 0.03) << "mean " << mean;
  EXPECT_NEAR(sd / std::pow(10.0, 0.3), 1.0, 0.10) << "sd " << sd;

  // The signal really oscillates at each texel's frequency. Inside a texel the
  // signal is s = 2a − 1 = sin(2π(φ + f·x)); any sampled sinusoid satisfies
  // s[n+1] + s[n−1] = 2·cos(ω)·s[n], ω = 2π·f·Δx, so the least-squares
  // c = Σ s[n](s[n+1] + s[n−1]) / (2·Σ s[n]²) recovers cos ω exactly up to
  // rounding, and f = acos(c)/(2π·Δx). The CSV holds shortest round-trip
  // decimals (exact), so the residual is position rounding (|x| <= 2000 mm:
  // ~1e-13 mm, i.e. ~1e-11 in s), giving a relative error far below the
  // 1e-6 used here. A signal at the wrong frequency (e.g. cycles/mm read as
  // radians/mm, or the previous texel's f) misses by orders of magnitude.
  const auto [x, a] = texel::parse_csv_columns(slurp(dir / "s.csv"), "s.csv");
  ASSERT_EQ(a.size(), 400000u);
  constexpr double dx = 0.005;
  const std::size_t per_texel = 200;
  double worst = 0.0;
  for (std::size_t k = 0; k < f.size(); ++k) {
    double num = 0.0;
    double den = 0.0;
    // Stay two samples clear of each boundary so n−1, n, n+1 share texel k.
    for (std::size_t n = k * per_texel + 2; n + 2 < (k + 1) * per_texel; ++n) {
      const double s0 = 2.0 * a[n] - 1.0;
      num += s0 * ((2.0 * a[n + 1] - 1.0) + (2.0 * a[n - 1] - 1.0));
      den += 2.0 * s0 * s0;
    }
    const double f_est = std::acos(num / den) / (2.0 * std::numbers::pi * dx);
    worst = std::max(worst, std::fabs(f_est / f[k] - 1.0));
    ASSERT_NEAR(f_est / f[k], 1.0, 1e-6) << "texel " << k << ": t.csv says " << f[k] << " cpm, signal has " << f_est;
  }
  EXPECT_EQ(x[1234], 1234 * dx);
  RecordProperty("worst_relative_frequency_error", std::to_string(worst));
}

// ------------------------------------------------------- bad input, by class

TEST_F(Cli, RejectsUnknownDevice) {
  expect_rejected({"render", "--device", "nosuch", "-o", "out.bin"}, "unknown device 'nosuch'");
}

TEST_F(Cli, RejectsNegativeTexelLength) {
  expect_rejected({"render", "--texel-length=-0.25", "-o", "out.bin"}, "--texel-length");
  expect_rejected({"render", "--texel-length", "0", "-o", "out.bin"}, "--texel-length");
}

TEST_F(Cli, RejectsNonFinitePitch) {
  for (const char* v : {"nan", "inf", "-inf", "NaN"})
    expect_rejected({"render", std::string("--central-pitch=") + v, "-o", "out.bin"}, "--central-pitch");
  expect_rejected({"render", "--irregularity=nan", "-o", "out.bin"}, "--irregularity");
}

TEST_F(Cli, RejectsPitchOutsideTheDeviceBand) {
  // 25 dB = 316 cpm, above the tpad's 94.3 cpm Nyquist; -25 dB below 0.01 cpm.
  expect_rejected({"render", "--central-pitch", "25", "-o", "out.bin"}, "outside the renderable band");
  expect_rejected({"render", "--central-pitch=-25", "-o", "out.bin"}, "outside the renderable band");
}

TEST_F(Cli, RejectsMalformedJson) {
  write("bad.texel.json", "{ \"format\": \"texel-document\", version: 1 }");
  expect_rejected({"render", "bad.texel.json", "-o", "out.bin"}, "malformed JSON");
}

TEST_F(Cli, RenderOfAnMpegHapticsFileSaysWhatItIsAndWhatReadsIt) {
  // Issue #37: a .hmpg (binary) was refused as "malformed JSON … line 1, column 1".
  write("x.hmpg", std::string("\x01\x02binary", 8));
  expect_rejected({"render", "x.hmpg", "-o", "out.png"}, "an MPEG-I Haptics file, not a Texel document");
  write("x.hjif", "{\"version\": \"2023\"}");
  expect_rejected({"render", "x.hjif", "-o", "out.png"}, "texel encode");
}

TEST_F(Cli, RejectsTruncatedDocument) {
  const std::string doc = valid_document();
  write("cut.texel.json", doc.substr(0, doc.size() / 2));
  expect_rejected({"render", "cut.texel.json", "-o", "out.bin"}, "malformed JSON");
}

TEST_F(Cli, RejectsUnknownKeyInDocument) {
  std::string doc = valid_document();
  doc.replace(doc.find("\"seed\""), 6, "\"sead\": 4, \"seed\"");  // a typo'd duplicate
  write("typo.texel.json", doc);
  expect_rejected({"render", "typo.texel.json", "-o", "out.bin"}, "texture has unknown key 'sead'");
}

TEST_F(Cli, RejectsWrongTypeInDocument) {
  std::string doc = valid_document();
  doc.replace(doc.find("\"texel_length_mm\": 0.25"), 23, "\"texel_length_mm\": \"0.25\"");
  write("type.texel.json", doc);
  expect_rejected({"render", "type.texel.json", "-o", "out.bin"}, "texture.texel_length_mm must be a number");
}

TEST_F(Cli, RejectsUnsupportedVersion) {
  std::string doc = valid_document();
  doc.replace(doc.find("\"version\": 1"), 12, "\"version\": 7");
  write("v7.texel.json", doc);
  expect_rejected({"render", "v7.texel.json", "-o", "out.bin"}, "version is 7");
}

TEST_F(Cli, RejectsUnwritableOutputDirectory) {
  expect_rejected({"render", "-o", "missing/out.bin"}, "does not exist");
  write("plainfile", "x");
  expect_rejected({"render", "-o", "plainfile/out.bin"}, "plainfile/out.bin");
  fs::create_directories(dir / "sub");
  fs::create_directories(dir / "taken.bin");
  expect_rejected({"render", "-o", "taken.bin"}, "is a directory");
  // A good main output with an unwritable --texels file writes neither.
  expect_rejected({"render", "-o", "out.bin", "--texels", "missing/t.csv"}, "missing/t.csv");
  if (::geteuid() != 0) {  // root ignores directory permissions
    fs::permissions(dir / "sub", fs::perms::owner_read | fs::perms::owner_exec);
    expect_rejected({"render", "-o", "sub/out.bin"}, "not writable");
    fs::permissions(dir / "sub", fs::perms::owner_all);
  }
}

TEST_F(Cli, RejectsBadOutputExtension) {
  expect_rejected({"render", "-o", "out.wav"}, "extension '.wav'");
  expect_rejected({"render", "-o", "noextension"}, "extension ''");
  expect_rejected({"render", "-o", "out.bin", "--texels", "t.txt"}, "--texels 't.txt' must be a .csv file");
}

TEST_F(Cli, RejectsCoarseStrengthAboveOne) {
  expect_rejected({"render", "--coarse-strength", "1.5", "-o", "out.bin"}, "--coarse-strength is 1.5");
  expect_rejected({"render", "--fine-strength=-0.5", "-o", "out.bin"}, "--fine-strength is -0.5");
}

TEST_F(Cli, RejectsBadPhaseValue) {
  expect_rejected({"render", "--phase", "sideways", "-o", "out.bin"}, "--phase is 'sideways'; allowed: continuous, reset");
}

TEST_F(Cli, RejectsMalformedCoarseProfileCsv) {
  write("bad.csv", "position_mm,value\n0,0.5\n10,high\n");
  expect_rejected({"render", "--coarse-profile", "bad.csv", "--coarse-strength", "1", "-o", "out.bin"}, "bad.csv:3");
}

TEST_F(Cli, RejectsNonIncreasingCoarseProfileCsv) {
  write("down.csv", "0,0.5\n10,0.6\n10,0.7\n");
  expect_rejected({"render", "--coarse-profile", "down.csv", "-o", "out.bin"}, "strictly increasing");
}

TEST_F(Cli, RejectsNonPositiveLengthOrSpacing) {
  expect_rejected({"render", "--length", "0", "-o", "out.bin"}, "--length is 0");
  expect_rejected({"render", "--length=-5", "-o", "out.bin"}, "--length is -5");
  expect_rejected({"render", "--spacing", "0", "-o", "out.bin"}, "--spacing is 0");
  expect_rejected({"render", "--spacing=-0.001", "-o", "out.bin"}, "--spacing is -0.001");
}

TEST_F(Cli, RejectsDocumentWithOverlappingRegions) {
  write("overlap.texel.json", R"({
  "format": "texel-document", "version": 1, "device": "tpad",
  "regions": [
    {"name": "left", "start_mm": 0, "length_mm": 60,
     "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 1}},
    {"name": "right", "start_mm": 50.88, "length_mm": 50.88,
     "texture": {"kind": "texel", "central_pitch_db": 10, "irregularity_db": -5, "texel_length_mm": 0.25, "seed": 2}}
  ]
})");
  expect_rejected({"render", "overlap.texel.json", "-o", "out.bin"}, "overlap");
}

TEST_F(Cli, FailedRenderLeavesAnExistingOutputUntouched) {
  write("out.bin", "previous contents");
  expect_rejected({"render", "--phase", "sideways", "-o", "out.bin"}, "--phase");
  EXPECT_EQ(slurp(dir / "out.bin"), "previous contents");
}

TEST_F(Cli, ValidDocumentWithRegionsRenders) {
  // The control for the document tests above: the same shapes, valid, succeed.
  write("ok.texel.json", valid_document());
  const Result r = run({"render", "ok.texel.json", "-o", "out.npy", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("\"samples\": 19200"), std::string::npos) << r.out;
  EXPECT_EQ(texel::parse_npy(slurp(dir / "out.npy"), "out.npy").size(), 19200u);
}

// ------------------------------------------------------- the one signal loader

namespace {

/// A PCM16 WAV of `channels` channels, a sine in channel 0.
std::string stereo_wav(unsigned channels, unsigned rate, std::size_t frames) {
  std::vector<std::int16_t> interleaved(frames * channels, 0);
  for (std::size_t i = 0; i < frames; ++i)
    interleaved[i * channels] = static_cast<std::int16_t>(16000 * std::sin(0.3 * static_cast<double>(i)));
  return texel::test_support::wav_bytes(channels, rate, interleaved);
}

}  // namespace

TEST_F(Cli, InfoSpectrumAndEncodeReadTheSameFileToTheSameSamples) {
  ASSERT_EQ(run({"render", "--central-pitch", "6", "--seed", "4", "-o", "m.bin"}).status, 0);
  ASSERT_EQ(run({"render", "--central-pitch", "6", "--seed", "4", "-o", "m.csv"}).status, 0);
  for (const std::string file : {"m.bin", "m.csv"}) {
    const std::vector<std::string> input = {file, "--device", "tpad", "--region", "10:60", "--json"};
    auto with = [&](std::vector<std::string> cmd) {
      cmd.insert(cmd.end(), input.begin(), input.end());
      return cmd;
    };
    const Result info = run(with({"info"}));
    const Result spectrum = run(with({"spectrum"}));
    const Result encode = run(with({"encode"}));
    ASSERT_EQ(info.status, 0) << info.err;
    ASSERT_EQ(spectrum.status, 0) << spectrum.err;
    ASSERT_EQ(encode.status, 0) << encode.err;
    const auto i = nlohmann::json::parse(info.out);
    const auto s = nlohmann::json::parse(spectrum.out);
    const auto e = nlohmann::json::parse(encode.out);
    EXPECT_EQ(i["amplitude"]["samples"], s["samples"]) << file;
    EXPECT_EQ(i["amplitude"]["samples"], e["samples"]) << file;
    EXPECT_NEAR(i["spacing_mm"].get<double>(), s["spacing_mm"].get<double>(), 1e-12) << file;
    EXPECT_NEAR(i["spacing_mm"].get<double>(), e["spacing_mm"].get<double>(), 1e-12) << file;
    EXPECT_NEAR(i["amplitude"]["mean"].get<double>(), s["mean_amplitude"].get<double>(), 1e-9) << file;
    EXPECT_GE(i["origin_mm"].get<double>(), 10.0) << file;
  }
}

TEST_F(Cli, InfoAndSpectrumReadRecordings) {
  write("r.wav", stereo_wav(1, 8000, 4000));
  const Result r = run({"info", "r.wav", "--swipe-speed", "100", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["kind"], "wav");
  EXPECT_EQ(j["sample_rate_hz"], 8000.0);
  EXPECT_NEAR(j["spacing_mm"].get<double>(), 100.0 / 8000, 1e-15);
  EXPECT_EQ(run({"spectrum", "r.wav", "--swipe-speed", "100", "--json"}).status, 0);
}

TEST_F(Cli, SignalErrorsNameTheFlags) {
  ASSERT_EQ(run({"render", "-o", "m.bin"}).status, 0);
  ASSERT_EQ(run({"render", "-o", "m.csv"}).status, 0);
  write("st.wav", stereo_wav(2, 8000, 400));
  expect_rejected({"info", "m.bin"}, "--device is required");
  expect_rejected({"spectrum", "m.bin"}, "--device is required");
  expect_rejected({"encode", "m.bin"}, "--device is required");
  expect_rejected({"spectrum", "m.csv", "--spacing", "0.5"}, "--spacing is 0.5 mm, but 'm.csv' is sampled every 0.0053 mm");
  expect_rejected({"info", "m.csv", "--region", "1000:2000"}, "--region [1000, 2000) mm holds 0 samples");
  expect_rejected({"info", "m.csv", "--region", "1:x"}, "--region '1:x' must be START:END");
  expect_rejected({"encode", "st.wav"}, "--swipe-speed is required");
  expect_rejected({"info", "st.wav", "--swipe-speed", "100"}, "--channel is not chosen, and 'st.wav' has 2 channels");
  expect_rejected({"info", "st.wav", "--swipe-speed", "100", "--channel", "2"}, "--channel is 2");
  expect_rejected({"info", "st.wav", "--swipe-speed", "100", "--channel", "left"}, "--channel is 'left'");
  expect_rejected({"info", "m.txt"}, "allowed: .bin");
  EXPECT_EQ(run({"info", "st.wav", "--swipe-speed", "100", "--channel", "mix"}).status, 0);
  EXPECT_EQ(run({"info", "st.wav", "--swipe-speed", "100", "--channel", "1"}).status, 2);  // silent: constant
}

// Issue #11, item 1: a document is transcoded, not re-estimated.
// Time recordings (issue #11 item 4): a texture swiped at a known speed by
// `texel swipe` (48 kHz, the friction map value under the finger) and
// written as WAV or time CSV encodes back to its parameters. The samples are
// the map interpolated at the finger's positions, so the perceptual fit
// decides (not the texel recovery of §4): Central Pitch within 1 dB, the
// decoded texture within 1 JND of the recording under the model, the
// coarse/fine decision right with strengths within 0.06, and Irregularity,
// which the model resolves weakly for narrow distributions, within 7 dB.
TEST_F(Cli, SwipeRecordingsEncodeBackToTheirParameters) {
  ASSERT_EQ(run({"render", "--central-pitch", "10", "--irregularity", "-5", "--seed", "7", "-o", "fine.texel.json"}).status, 0);
  ASSERT_EQ(run({"render", "--central-pitch", "10", "--irregularity", "-5", "--seed", "7", "--coarse-sine", "5",
                 "--coarse-strength", "0.6", "--fine-strength", "0.5", "-o", "two.texel.json"})
                .status,
            0);
  struct Case {
    std::string doc, speed, out;
    bool coarse;
  };
  for (const Case& c : {Case{"fine", "100", "fine100.wav", false}, Case{"fine", "50", "fine50.csv", false},
                        Case{"two", "100", "two100.wav", true}, Case{"two", "50", "two50.csv", true}}) {
    const double seconds = 95.0 / std::stod(c.speed);  // one stroke over 95 mm of the 101.8 mm tpad
    ASSERT_EQ(run({"swipe", c.doc + ".texel.json", "--speed", c.speed, "--duration", std::to_string(seconds), "--output",
                   "amplitude", "-o", c.out})
                  .status,
              0)
        << c.out;
    const Result e = run({"encode", c.out, "--swipe-speed", c.speed, "--json", "-o", "x.texel"});
    ASSERT_EQ(e.status, 0) << e.err;
    const auto j = nlohmann::json::parse(e.out);
    const auto& est = j["estimate"];
    SCOPED_TRACE(c.out + ": " + est.dump());
    EXPECT_EQ(j["method"], "estimated");
    EXPECT_NEAR(est["central_pitch_db"].get<double>(), 10.0, 1.0);
    EXPECT_NEAR(est["irregularity_db"].get<double>(), -5.0, 7.0);
    EXPECT_LT(j["model"]["distance_jnd"].get<double>(), 1.0);
    EXPECT_EQ(est["coarse"].get<bool>(), c.coarse);
    EXPECT_NEAR(est["coarse_strength"].get<double>(), c.coarse ? 0.6 : 0.0, 0.06);
    EXPECT_NEAR(est["fine_strength"].get<double>(), c.coarse ? 0.5 : 1.0, 0.06);
  }
  // The fit's search is switchable (--fit), and named in --json.
  const Result nm = run({"encode", "fine50.csv", "--swipe-speed", "50", "--fit", "simplex", "--json"});
  ASSERT_EQ(nm.status, 0) << nm.err;
  EXPECT_EQ(nlohmann::json::parse(nm.out)["model"]["fit"], "simplex");
  expect_rejected({"encode", "fine50.csv", "--swipe-speed", "50", "--fit", "newton"}, "--fit is 'newton'");
  // A 3-column CSV whose header is not time_s,… is refused, naming the layout.
  write("bad.csv", "position_mm,x,amplitude\n0,0,0.5\n0.1,0,0.6\n0.2,0,0.7\n");
  expect_rejected({"encode", "bad.csv"}, "time_s,position_mm,value");
}

// The device's frequency response (docs/format.md): the encoder's model
// feels through it by default (--display-response device, anchored by the
// texture as drawn: --drawn-weight) and as drawn with --display-response
// flat; the player limits to it by default (--response limit) and plays as
// before with --response off.
TEST_F(Cli, DisplayResponseReachesTheEncoderAndThePlayer) {
  write("d.texel.json", valid_document());
  ASSERT_EQ(run({"render", "d.texel.json", "-o", "m.bin"}).status, 0);
  const Result dev = run({"encode", "m.bin", "--device", "tpad", "--json"});
  ASSERT_EQ(dev.status, 0) << dev.err;
  const auto m = nlohmann::json::parse(dev.out)["model"];
  EXPECT_EQ(m["display_response"], "device");
  EXPECT_EQ(m["display"]["corner_hz"].get<double>(), 400.0);
  EXPECT_EQ(m["display"]["order"].get<int>(), 1);
  EXPECT_EQ(m["drawn_weight"].get<double>(), 1.0);
  EXPECT_TRUE(m["input"].contains("drawn_pitch_db"));
  const Result flat = run({"encode", "m.bin", "--device", "tpad", "--display-response", "flat", "--json"});
  ASSERT_EQ(flat.status, 0) << flat.err;
  EXPECT_EQ(nlohmann::json::parse(flat.out)["model"]["display_response"], "flat");
  EXPECT_FALSE(nlohmann::json::parse(flat.out)["model"].contains("display"));
  // generic is flat: nothing in the loop whatever the switch.
  ASSERT_EQ(run({"render", "d.texel.json", "--device", "generic", "-o", "g.npy"}).status, 0);
  const Result generic = run({"encode", "g.npy", "--device", "generic", "--json"});
  ASSERT_EQ(generic.status, 0) << generic.err;
  EXPECT_FALSE(nlohmann::json::parse(generic.out)["model"].contains("display"));
  expect_rejected({"encode", "m.bin", "--device", "tpad", "--display-response", "sideways"}, "--display-response");
  expect_rejected({"encode", "m.bin", "--device", "tpad", "--drawn-weight", "-1"}, "--drawn-weight");
  ASSERT_EQ(run({"swipe", "d.texel.json", "--duration", "0.2", "--output", "amplitude", "-o", "limit.csv"}).status, 0);
  ASSERT_EQ(
      run({"swipe", "d.texel.json", "--duration", "0.2", "--output", "amplitude", "--response", "off", "-o", "off.csv"}).status,
      0);
  EXPECT_NE(slurp(dir / "limit.csv"), slurp(dir / "off.csv"));  // the tpad's response limit (3.98 kHz at 48 kHz) filtered
  expect_rejected({"swipe", "d.texel.json", "--response", "equalize", "-o", "x.csv"}, "--response");
}

TEST_F(Cli, EncodeTranscodesADocumentExactly) {
  ASSERT_EQ(run({"render", "--central-pitch", "8", "--irregularity", "0", "--texel-length", "0.5", "--seed", "3", "--device",
                 "tpad", "-o", "d.texel.json"})
                .status,
            0);
  const Result e = run({"encode", "d.texel.json", "-o", "d.texel", "--json"});
  ASSERT_EQ(e.status, 0) << e.err;
  EXPECT_EQ(e.err, "");
  const auto j = nlohmann::json::parse(e.out);
  EXPECT_EQ(j["method"], "transcoded");
  EXPECT_EQ(j["exact"], true);
  EXPECT_EQ(j["parameters"]["central_pitch_db"], 8.0);
  EXPECT_EQ(j["parameters"]["seed"], 3);
  ASSERT_EQ(run({"decode", "d.texel", "--device", "tpad", "-o", "a.bin"}).status, 0);
  ASSERT_EQ(run({"render", "d.texel.json", "--device", "tpad", "-o", "b.bin"}).status, 0);
  EXPECT_EQ(slurp(dir / "a.bin"), slurp(dir / "b.bin"));
  // Re-encoding the bitstream gives the same bytes.
  ASSERT_EQ(run({"encode", "d.texel", "-o", "e.texel"}).status, 0);
  EXPECT_EQ(slurp(dir / "e.texel"), slurp(dir / "d.texel"));
  // --estimate re-estimates from the samples.
  const Result est = run({"encode", "d.texel.json", "--estimate", "--json"});
  ASSERT_EQ(est.status, 0) << est.err;
  EXPECT_EQ(nlohmann::json::parse(est.out)["method"], "estimated");
  // Estimation flags with a transcoded input are refused, naming --estimate.
  expect_rejected({"encode", "d.texel.json", "--seed", "4", "-o", "x.texel"}, "--estimate");
  // A value between the bitstream's steps: a warning, and --json says so.
  ASSERT_EQ(run({"render", "--central-pitch", "8.004", "--seed", "3", "-o", "q.texel.json"}).status, 0);
  const Result q = run({"encode", "q.texel.json", "--json"});
  ASSERT_EQ(q.status, 0) << q.err;
  EXPECT_NE(q.err.find("warning: not exact: central_pitch_db 8.004 is stored as 8"), std::string::npos) << q.err;
  const auto qj = nlohmann::json::parse(q.out);
  EXPECT_EQ(qj["exact"], false);
  EXPECT_EQ(qj["losses"].size(), 1u);
}
