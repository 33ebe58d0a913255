// Pieces of `texel spectrum` that `texel atlas` reuses: reading any file the
// CLI writes as a signal, and building the spectrum figure for a map.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "texel/spectrum.hpp"
#include "texel/spectrum_plot.hpp"

namespace texel::cli {

/// A uniformly sampled map read from a file.
struct LoadedSignal {
  std::vector<double> samples;
  double spacing_mm = 0.0;
  double origin_mm = 0.0;
  std::string source;  ///< "device tpad (u16le)", "csv", "npy", "document"
};

/// Reads .bin (needs `device`), .csv (position_mm,amplitude), .npy (needs
/// `device` or `spacing_mm`) or .texel.json (rendered on its device; `region`
/// picks one region by name or index). Throws InvalidArgument / FormatError.
LoadedSignal load_signal(const std::string& path, const std::optional<std::string>& device,
                         const std::optional<double>& spacing_mm, const std::optional<std::string>& region);

/// The excerpt-over-spectrum figure data for a map and its analysis.
SpectrumPlot make_spectrum_plot(const std::string& title, const LoadedSignal& signal, const SpectralReport& report,
                                std::optional<double> swipe_speed_mm_s);

}  // namespace texel::cli
