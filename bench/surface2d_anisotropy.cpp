// texel_surface2d_anisotropy: the measurement that chose the 2-D model's
// isotropic field (docs/algorithm.md §11.3). For every (P, I, L) of the grid
// covering the shipped protocols' textures and every candidate design,
// straight scans along 36 directions (0° … 175°) analysed with the 1-D
// spectrum tools: Central Pitch (log centroid) and Irregularity (log spread)
// per direction, their spread across directions (max − min), their mean
// against the 1-D texture's own, and the stationary isotropic bound.
//
//   texel_surface2d_anisotropy [--quick] [--scans 16] [--samples 4096] [--pitches 0,5.67] [--irregularities 5]
//                              [--lengths 0.25] [--designs cells,spectral,tile] [--figure spread.svg] [--csv table.csv]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "texel/plot.hpp"
#include "texel/surface2d.hpp"

using namespace texel;

namespace {

struct Row {
  double p, i, l;
  std::string design;
  double line_p, line_i;  // the 1-D texture's measured values
  double mean_p, mean_i, spread_p, spread_i;
  double bound_p, bound_i;  // the stationary bound's prediction (A·S2), and its target
  double target_p, target_i;
  double matched_p, matched_i;  // the moment fit's prediction
  std::vector<DirectionStats> per_direction;
};

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int scans = 16;
  std::size_t samples = 4096;
  std::vector<double> only_pitches, only_irregularities, only_lengths;
  std::vector<Field2D> designs{Field2D::cells, Field2D::spectral, Field2D::tile};
  const auto numbers = [](char* text, std::vector<double>& out) {
    for (char* t = std::strtok(text, ","); t; t = std::strtok(nullptr, ",")) out.push_back(std::atof(t));
  };
  std::string figure, csv;
  for (int a = 1; a < argc; ++a) {
    if (!std::strcmp(argv[a], "--quick")) quick = true;
    if (!std::strcmp(argv[a], "--figure") && a + 1 < argc) figure = argv[++a];
    if (!std::strcmp(argv[a], "--csv") && a + 1 < argc) csv = argv[++a];
    if (!std::strcmp(argv[a], "--scans") && a + 1 < argc) scans = std::atoi(argv[++a]);
    if (!std::strcmp(argv[a], "--samples") && a + 1 < argc) samples = static_cast<std::size_t>(std::atol(argv[++a]));
    // Comma-separated subsets of the grid (dB, dB, mm) and of the designs, to split a sweep.
    if (!std::strcmp(argv[a], "--pitches") && a + 1 < argc) numbers(argv[++a], only_pitches);
    if (!std::strcmp(argv[a], "--irregularities") && a + 1 < argc) numbers(argv[++a], only_irregularities);
    if (!std::strcmp(argv[a], "--lengths") && a + 1 < argc) numbers(argv[++a], only_lengths);
    if (!std::strcmp(argv[a], "--designs") && a + 1 < argc) {
      designs.clear();
      for (char* t = std::strtok(argv[++a], ","); t; t = std::strtok(nullptr, ","))
        designs.push_back(parse_field2d(t, "--designs"));
    }
  }
  // The protocols' textures (examples/protocols: P 0 … 15.3 dB, I −10 … 5 dB
  // moments, L 0.25 and 1 mm).
  const std::vector<double> pitches =
      quick ? std::vector<double>{6.0} : (only_pitches.empty() ? std::vector<double>{0.0, 5.67, 11.0, 15.26} : only_pitches);
  const std::vector<double> irregularities =
      quick ? std::vector<double>{-5.0}
            : (only_irregularities.empty() ? std::vector<double>{-10.0, -5.0, 0.0, 5.0} : only_irregularities);
  const std::vector<double> lengths =
      quick ? std::vector<double>{0.25} : (only_lengths.empty() ? std::vector<double>{0.25, 1.0} : only_lengths);
  std::vector<Row> rows;
  std::printf("%6s %6s %5s %-9s | %7s %7s | %7s %7s %6s %6s | %7s %7s | %7s %7s\n", "P_dB", "I_dB", "L_mm", "design", "1D_P",
              "1D_I", "mean_P", "mean_I", "sprP", "sprI", "mom_P", "mom_I", "nnls_P", "nnls_I");
  for (double p : pitches)
    for (double irr : irregularities)
      for (double l : lengths) {
        TexelSpec spec;
        spec.central_pitch = Decibels(p);
        spec.irregularity = Decibels(irr);
        spec.texel_length = Millimetres(l);
        spec.seed = 7;
        // Scans sampled at 16× the mean frequency (at most the tpad's grid):
        // the band the scans can carry is the fields' band top.
        const double mean = std::pow(10.0, p / 10.0);
        const CyclesPerMm top(std::min(94.33962264150944, 16.0 * mean));
        ScanOptions options;
        options.spacing = Millimetres(0.5 / top.value());
        options.samples = samples;
        options.scans = scans;
        const DirectionStats line = measure_line(spec, top, options);
        for (Field2D design : designs) {
          const FineField2D field(spec, design, 0.0, top);
          Row r{};
          r.p = p;
          r.i = irr;
          r.l = l;
          r.design = std::string(to_string(design));
          r.line_p = line.log_centroid_db;
          r.line_i = line.log_spread_db;
          r.per_direction = measure_scans(field, options);
          double lo_p = 1e9, hi_p = -1e9, lo_i = 1e9, hi_i = -1e9, sp = 0, si = 0;
          for (const auto& d : r.per_direction) {
            lo_p = std::min(lo_p, d.log_centroid_db);
            hi_p = std::max(hi_p, d.log_centroid_db);
            lo_i = std::min(lo_i, d.log_spread_db);
            hi_i = std::max(hi_i, d.log_spread_db);
            sp += d.log_centroid_db;
            si += d.log_spread_db;
          }
          const double n = static_cast<double>(r.per_direction.size());
          r.mean_p = sp / n;
          r.mean_i = si / n;
          r.spread_p = hi_p - lo_p;
          r.spread_i = hi_i - lo_i;
          TexelSpec band = spec;
          const IsotropicBound b = isotropic_bound(PitchDistribution([&] {
                                                     PitchDistributionConfig c;
                                                     c.central_pitch = band.central_pitch;
                                                     c.irregularity = band.irregularity;
                                                     c.band_min = band.band_min;
                                                     c.band_max = top;
                                                     return c;
                                                   }()),
                                                   top);
          r.bound_p = b.scan_log_centroid_db;
          r.bound_i = b.scan_log_spread_db;
          r.target_p = b.target_log_centroid_db;
          r.target_i = b.target_log_spread_db;
          r.matched_p = b.matched_log_centroid_db;
          r.matched_i = b.matched_log_spread_db;
          std::printf(
              "%6.2f %6.2f %5.2f %-9s | %7.2f %7.2f | %7.2f %7.2f %6.2f %6.2f | %7.2f %7.2f | %7.2f %7.2f (target %6.2f %6.2f)\n",
              p, irr, l, r.design.c_str(), r.line_p, r.line_i, r.mean_p, r.mean_i, r.spread_p, r.spread_i, r.matched_p,
              r.matched_i, r.bound_p, r.bound_i, r.target_p, r.target_i);
          std::fflush(stdout);
          rows.push_back(std::move(r));
        }
      }
  for (Field2D design : designs) {
    const std::string name(to_string(design));
    // Spread across directions (goal: P 0.5 dB, I 1 dB) and, for the
    // stationary designs, the mean over directions against the moment bound
    // (the best a stationary isotropic field does; goal within 0.5 dB).
    double spread_p = 0, spread_i = 0, off_p = 0, off_i = 0;
    for (const auto& r : rows)
      if (r.design == name) {
        spread_p = std::max(spread_p, r.spread_p);
        spread_i = std::max(spread_i, r.spread_i);
        off_p = std::max(off_p, std::fabs(r.mean_p - r.matched_p));
        off_i = std::max(off_i, std::fabs(r.mean_i - r.matched_i));
      }
    std::printf("%s: worst spread across %d directions P %.2f dB, I %.2f dB; worst |mean - moment bound| P %.2f dB, I %.2f dB\n",
                name.c_str(), ScanOptions{}.directions, spread_p, spread_i, off_p, off_i);
  }
  if (!csv.empty()) {
    std::ofstream out(csv);
    out << "central_pitch_db,irregularity_db,texel_length_mm,design,line_p_db,line_i_db,mean_p_db,mean_i_db,spread_p_db,"
           "spread_i_db,nnls_p_db,nnls_i_db,target_p_db,target_i_db,moment_p_db,moment_i_db\n";
    for (const auto& r : rows)
      out << r.p << "," << r.i << "," << r.l << "," << r.design << "," << r.line_p << "," << r.line_i << "," << r.mean_p << ","
          << r.mean_i << "," << r.spread_p << "," << r.spread_i << "," << r.bound_p << "," << r.bound_i << "," << r.target_p
          << "," << r.target_i << "," << r.matched_p << "," << r.matched_i << "\n";
  }
  if (!figure.empty()) {
    // Per direction: the deviation from the direction mean, every texture
    // of the grid one line, one panel per design and quantity.
    Figure f;
    f.width_px = 1200;
    f.height_px = 400 * static_cast<int>(designs.size());
    f.columns = 2;
    f.title = "2-D fields: straight scans along 36 directions, deviation from the mean over directions";
    for (Field2D shown : designs)
      for (int q = 0; q < 2; ++q) {
        const std::string design(to_string(shown));
        Panel panel;
        panel.title = design + (q == 0 ? ": Central Pitch (log centroid)" : ": Irregularity (log spread)");
        panel.x.label = "scan direction (deg)";
        panel.y.label = "deviation (dB)";
        panel.y.min = q == 0 ? -0.5 : -1.0;
        panel.y.max = q == 0 ? 0.5 : 1.0;
        panel.legend = false;
        for (const auto& r : rows) {
          if (r.design != design) continue;
          LineSeries s;
          const double m = q == 0 ? r.mean_p : r.mean_i;
          for (const auto& d : r.per_direction) {
            s.x.push_back(d.direction_deg);
            s.y.push_back((q == 0 ? d.log_centroid_db : d.log_spread_db) - m);
          }
          s.width_px = 1.0;
          panel.lines.push_back(std::move(s));
        }
        f.panels.push_back(std::move(panel));
      }
    // Panels ordered design by design, P then I: 2 columns.
    save_figure(f, figure);
  }
  return 0;
}
