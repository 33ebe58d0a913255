// Turning a rendered surface into the file a user asked for. Shared by every
// command that produces a texture (render, reference, decode, ...).
#pragma once

#include <string>
#include <vector>

#include "common.hpp"
#include "texel/document.hpp"

namespace texel::cli {

/// The amplitude map of a whole surface, with a progress line for large grids.
std::vector<double> render_map(const Surface& surface);

/// Writes `surface` to `path` in the format its extension picks. `doc` is
/// written for .texel.json; `frequencies_cpm` feeds the plot's histogram.
/// Atomic, and nothing is written if anything fails.
void write_rendered(const std::string& path, const Document& doc, const Surface& surface, const std::vector<double>& map,
                    const std::vector<double>& frequencies_cpm, std::vector<PendingFile> extra = {});

/// Texel frequencies of every Texel region (for histograms and summaries).
std::vector<double> texel_frequencies(const Surface& surface);

}  // namespace texel::cli
