// texel spectrum: magnitude spectrum, Welch PSD, peak list, spectral
// centroids, spread and band energies of any map the CLI writes or reads,
// with a temporal-frequency view for a swipe speed and the researchers'
// figure (6 mm excerpt above a log-frequency spectrum).
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "render_output.hpp"
#include "spectrum_common.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/matfile.hpp"
#include "texel/plot.hpp"

namespace texel::cli {
namespace {

using detail::fixed;
using detail::num;
using ordered = nlohmann::ordered_json;

double db_of(double cpm) { return 10.0 * std::log10(cpm); }

std::pair<CyclesPerMm, CyclesPerMm> parse_band(const std::string& text) {
  const auto colon = text.find(':');
  auto number = [&](std::string_view t) {
    double v = 0.0;
    const auto res = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || res.ec != std::errc() || res.ptr != t.data() + t.size())
      throw InvalidArgument("--band '" + text + "' must be LOW:HIGH in cycles/mm, e.g. 1:10");
    return v;
  };
  if (colon == std::string::npos) throw InvalidArgument("--band '" + text + "' must be LOW:HIGH in cycles/mm, e.g. 1:10");
  const double lo = number(std::string_view(text).substr(0, colon));
  const double hi = number(std::string_view(text).substr(colon + 1));
  if (!(lo >= 0.0 && hi > lo && std::isfinite(hi)))
    throw InvalidArgument("--band '" + text + "' needs 0 <= LOW < HIGH (cycles/mm)");
  return {CyclesPerMm(lo), CyclesPerMm(hi)};
}

struct Args {
  std::string file;
  SignalArgs input;
  bool json = false;
  std::optional<std::string> output;
  std::string mat_version = "5";
  std::optional<std::string> spectrum_csv;
  std::optional<std::string> psd_csv;
  std::string window = "blackman-harris";
  int zero_pad = 4;
  double threshold_db = -40.0;
  std::size_t max_peaks = 32;
  std::size_t welch_segment = 0;
  double welch_overlap = 0.5;
  std::vector<std::string> bands;
  double excerpt_mm = 6.0;
};

ordered report_json(const Args& a, const Signal& sig, const SpectralReport& r) {
  // A plain flag and value rather than optional<MmPerSecond>: GCC 12 warns
  // (falsely) about the optional's payload inside nlohmann's conversions.
  const bool has_speed = a.input.swipe_speed.has_value();
  const MmPerSecond speed(a.input.swipe_speed.value_or(1.0));
  const MmPerSecond* v = has_speed ? &speed : nullptr;
  ordered j;
  j["file"] = a.file;
  j["source"] = sig.description;
  j["samples"] = sig.samples.size();
  j["spacing_mm"] = sig.spacing.value();
  j["length_mm"] = static_cast<double>(sig.samples.size()) * sig.spacing.value();
  j["nyquist_cpm"] = 0.5 / sig.spacing.value();
  j["resolution_cpm"] = r.spectrum.resolution.value();
  j["window"] = std::string(to_string(r.spectrum.window));
  j["nfft"] = r.spectrum.nfft;
  if (v) j["swipe_speed_mm_s"] = v->value();
  j["mean_amplitude"] = r.mean;
  j["rms_amplitude"] = r.rms;
  j["peak_threshold_db"] = a.threshold_db;
  j["peaks"] = ordered::array();
  for (const auto& p : r.peaks) {
    ordered pj;
    pj["frequency_cpm"] = p.frequency.value();
    pj["frequency_db"] = db_of(p.frequency.value());
    if (v) pj["frequency_hz"] = temporal(p.frequency, *v).value();
    pj["amplitude"] = p.amplitude;
    pj["level_db"] = p.level.value();
    j["peaks"].push_back(pj);
  }
  const auto& s = r.summary;
  ordered sj;
  sj["centroid_cpm"] = s.centroid.value();
  sj["log_centroid_db"] = s.log_centroid.value();
  sj["log_centroid_cpm"] = std::pow(10.0, s.log_centroid.value() / 10.0);
  sj["spread_cpm"] = s.spread.value();
  sj["log_spread_db"] = s.log_spread.value();
  if (v) {
    sj["centroid_hz"] = temporal(s.centroid, *v).value();
    sj["log_centroid_hz"] = temporal(CyclesPerMm(std::pow(10.0, s.log_centroid.value() / 10.0)), *v).value();
    sj["spread_hz"] = s.spread.value() * v->value();
  }
  j["summary"] = sj;
  j["bands"] = ordered::array();
  for (const auto& b : r.bands) {
    ordered bj{{"lo_cpm", b.lo.value()}, {"hi_cpm", b.hi.value()}};
    if (v) {
      bj["lo_hz"] = b.lo.value() * v->value();
      bj["hi_hz"] = b.hi.value() * v->value();
    }
    bj["mean_square"] = b.mean_square;
    bj["fraction"] = b.fraction;
    j["bands"].push_back(bj);
  }
  j["welch"] = {
      {"window", "hann"}, {"segment_samples", r.psd.segment}, {"segments", r.psd.segments}, {"bin_cpm", r.psd.bin.value()}};
  return j;
}

void print_report(const Args& a, const Signal& sig, const SpectralReport& r) {
  const std::optional<double> v = a.input.swipe_speed;
  std::cout << a.file << ": " << sig.samples.size() << " samples × " << num(sig.spacing.value()) << " mm ("
            << fixed(static_cast<double>(sig.samples.size()) * sig.spacing.value(), 2) << " mm), " << sig.description << "\n";
  std::cout << "resolution " << num(r.spectrum.resolution.value()) << " cpm, Nyquist " << fixed(0.5 / sig.spacing.value(), 2)
            << " cpm, window " << to_string(r.spectrum.window) << "\n";
  std::cout << "peaks (within " << num(a.threshold_db) << " dB of the highest):\n";
  std::cout << "  frequency_cpm      dB re 1 cpm   amplitude   level_dB" << (v ? "   frequency_Hz" : "") << "\n";
  for (const auto& p : r.peaks) {
    std::cout << "  " << std::setw(13) << fixed(p.frequency.value(), 4) << std::setw(14) << fixed(db_of(p.frequency.value()), 2)
              << std::setw(12) << fixed(p.amplitude, 5) << std::setw(11) << fixed(p.level.value(), 2);
    if (v) std::cout << std::setw(15) << fixed(p.frequency.value() * *v, 2);
    std::cout << "\n";
  }
  const auto& s = r.summary;
  std::cout << "spectral centroid " << fixed(s.centroid.value(), 4) << " cpm"
            << (v ? " (" + fixed(s.centroid.value() * *v, 2) + " Hz)" : "") << ", log-frequency centroid "
            << fixed(s.log_centroid.value(), 2) << " dB re 1 cpm (" << fixed(std::pow(10.0, s.log_centroid.value() / 10.0), 4)
            << " cpm)\n";
  std::cout << "spectral spread " << fixed(s.spread.value(), 4) << " cpm, log spread " << fixed(s.log_spread.value(), 2)
            << " dB\n";
  std::cout << "band energy (mean-square amplitude, share):\n";
  for (const auto& b : r.bands)
    std::cout << "  " << std::setw(8) << num(b.lo.value()) << " … " << std::setw(8) << fixed(b.hi.value(), 4) << " cpm  "
              << std::setw(12) << num(b.mean_square) << "  " << fixed(100.0 * b.fraction, 2) << " %\n";
}

}  // namespace

SpectrumPlot make_spectrum_plot(const std::string& title, const Signal& sig, const SpectralReport& r,
                                std::optional<double> swipe_speed_mm_s) {
  SpectrumPlot p;
  p.title = title;
  const double length = static_cast<double>(sig.samples.size()) * sig.spacing.value();
  p.excerpt = Millimetres(std::min(6.0, length));
  const auto n = std::min(sig.samples.size(), static_cast<std::size_t>(std::ceil(p.excerpt / sig.spacing)) + 1);
  for (std::size_t i = 0; i < n; ++i) {
    p.positions_mm.push_back(sig.origin.value() + static_cast<double>(i) * sig.spacing.value());
    p.amplitudes.push_back(sig.samples[i]);
  }
  p.spectrum = r.spectrum;
  p.peaks = r.peaks;
  if (swipe_speed_mm_s) p.swipe_speed = MmPerSecond(*swipe_speed_mm_s);
  return p;
}

/// The .mat variables of a spectrum (docs/format.md "MATLAB .mat"): N×1
/// columns, and the peaks as a struct of columns.
std::vector<mat::Variable> spectrum_variables(const std::string& source, const Signal& sig, const SpectralReport& r) {
  using mat::Matrix;
  std::vector<double> pf, pa, pl;
  for (const Peak& p : r.peaks) pf.push_back(p.frequency.value()), pa.push_back(p.amplitude), pl.push_back(p.level.value());
  mat::Struct peaks;
  peaks.add("frequency_cpm", Matrix::column(std::move(pf)))
      .add("amplitude", Matrix::column(std::move(pa)))
      .add("level_db", Matrix::column(std::move(pl)));
  mat::Struct params;
  params.add("source", mat::Text{source})
      .add("spacing_mm", Matrix::scalar(sig.spacing.value()))
      .add("samples", Matrix::scalar(static_cast<double>(sig.samples.size())))
      .add("window", mat::Text{std::string(to_string(r.spectrum.window))})
      .add("nfft", Matrix::scalar(static_cast<double>(r.spectrum.nfft)))
      .add("bin_cpm", Matrix::scalar(r.spectrum.bin.value()))
      .add("psd_segment", Matrix::scalar(static_cast<double>(r.psd.segment)))
      .add("mean", Matrix::scalar(r.mean))
      .add("rms", Matrix::scalar(r.rms));
  return {{"frequency_cpm", Matrix::column(r.spectrum.frequency_cpm)},
          {"magnitude", Matrix::column(r.spectrum.magnitude)},
          {"psd_frequency_cpm", Matrix::column(r.psd.frequency_cpm)},
          {"psd", Matrix::column(r.psd.density)},
          {"peaks", std::move(peaks)},
          {"params", std::move(params)}};
}

void register_spectrum(CLI::App& app) {
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("spectrum", "Spectrum of a texture map: peaks, centroids, spread, band energy, plot");
  cmd->add_option("file", a->file, kInputHelp)->required();
  add_signal_options(*cmd, a->input);  // --swipe-speed also adds temporal frequencies (Hz = cycles/mm × mm/s)
  cmd->add_flag("--json", a->json, "Print the report as JSON");
  cmd->add_option("-o,--output", a->output,
                  "Plot: .png or .svg (excerpt on top, spectrum below on a log-frequency axis); or .mat (MATLAB: "
                  "frequency_cpm, magnitude, psd_frequency_cpm, psd, peaks)");
  cmd->add_option("--mat-version", a->mat_version, "MATLAB file version of a .mat output: 5 (default) or 7.3 (HDF5)")
      ->default_str("5");
  cmd->add_option("--spectrum-csv", a->spectrum_csv, "Also write frequency_cpm,magnitude rows");
  cmd->add_option("--psd-csv", a->psd_csv, "Also write frequency_cpm,psd rows (Welch, a²/(cycle/mm))");
  const std::string g = "Analysis";
  cmd->add_option("--window", a->window,
                  "Magnitude-spectrum window: blackman-harris | hann | flat-top | rectangular [blackman-harris]")
      ->group(g);
  cmd->add_option("--zero-pad", a->zero_pad, "Zero padding factor 1 … 16 [4]")->group(g);
  cmd->add_option("--threshold", a->threshold_db, "Peak threshold, dB below the highest peak [-40]")->group(g);
  cmd->add_option("--max-peaks", a->max_peaks, "Most peaks to list [32]")->group(g);
  cmd->add_option("--welch-segment", a->welch_segment, "Welch segment, samples (0 = auto, about a quarter of the map) [0]")
      ->group(g);
  cmd->add_option("--welch-overlap", a->welch_overlap, "Welch overlap, 0 … 0.95 [0.5]")->group(g);
  cmd->add_option("--band", a->bands, "Band for band energy, LOW:HIGH in cycles/mm (repeatable) [decades]")->group(g);
  cmd->callback([a] {
    // Validate everything cheap before reading or rendering anything.
    const mat::MatVersion mat_version = mat::parse_mat_version(a->mat_version);
    const bool mat_output = a->output && output_extension(*a->output) == ".mat";
    if (a->output) {
      if (!mat_output) (void)plot_format_for_path(*a->output);
      check_writable(*a->output);
    }
    for (const auto* p : {&a->spectrum_csv, &a->psd_csv})
      if (*p) {
        if (output_extension(**p) != ".csv") throw InvalidArgument("'" + **p + "' must be a .csv file");
        check_writable(**p);
      }
    if (a->max_peaks < 1 || a->max_peaks > 100000)
      throw InvalidArgument("--max-peaks is " + std::to_string(a->max_peaks) + "; allowed: 1 … 100000");
    if (!(a->threshold_db <= 0.0 && a->threshold_db >= -300.0))
      throw InvalidArgument("--threshold is " + num(a->threshold_db) + " dB; allowed: -300 … 0");
    AnalysisOptions opt;
    opt.spectrum.window = parse_window(a->window, "--window");
    opt.spectrum.zero_pad = a->zero_pad;
    if (a->zero_pad < 1 || a->zero_pad > 16)
      throw InvalidArgument("--zero-pad is " + std::to_string(a->zero_pad) + "; allowed: 1 … 16");
    opt.welch.segment = a->welch_segment;
    opt.welch.overlap = a->welch_overlap;
    if (!(a->welch_overlap >= 0.0 && a->welch_overlap <= 0.95))
      throw InvalidArgument("--welch-overlap is " + num(a->welch_overlap) + "; allowed: 0 … 0.95");
    opt.peaks.threshold = DecibelsLevel(a->threshold_db);
    opt.peaks.max_peaks = a->max_peaks;
    for (const auto& b : a->bands) opt.bands.push_back(parse_band(b));

    const Signal sig = load_input(a->file, a->input);
    if (sig.samples.size() < 16)
      throw InvalidArgument("'" + a->file + "' holds " + std::to_string(sig.samples.size()) +
                            " samples; a spectrum needs at least 16");
    const SpectralReport r = analyse_spectrum(sig.samples, sig.spacing, opt);

    std::vector<PendingFile> files;
    if (a->spectrum_csv)
      files.push_back(
          {*a->spectrum_csv, csv_columns("frequency_cpm", "magnitude", r.spectrum.frequency_cpm, r.spectrum.magnitude)});
    if (a->psd_csv) files.push_back({*a->psd_csv, csv_columns("frequency_cpm", "psd", r.psd.frequency_cpm, r.psd.density)});
    if (a->output) {
      if (mat_output)
        mat::write_mat(*a->output, spectrum_variables(a->file, sig, r), {.version = mat_version});  // atomic on its own
      else
        plot_spectrum(make_spectrum_plot(a->file, sig, r, a->input.swipe_speed), *a->output);  // atomic on its own
      try {
        commit_files(files);
      } catch (...) {
        std::remove(a->output->c_str());
        throw;
      }
    } else {
      commit_files(files);
    }
    if (a->json)
      print_json(report_json(*a, sig, r));
    else
      print_report(*a, sig, r);
  });
}

}  // namespace texel::cli
