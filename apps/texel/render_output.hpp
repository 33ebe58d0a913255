// Turning a rendered surface into the file a user asked for. Shared by every
// command that produces a texture (render, reference, decode, ...).
#pragma once

#include <string>
#include <vector>

#include "common.hpp"
#include "texel/document.hpp"
#include "texel/matfile.hpp"

namespace texel::cli {

/// The amplitude map of a whole surface, with a progress line for large grids.
std::vector<double> render_map(const Surface& surface);

/// Writes `surface` to `path` in the format its extension picks. `doc` is
/// written for .texel.json; `frequencies_cpm` feeds the plot's histogram;
/// `mat_version` picks v5 or v7.3 for .mat (docs/format.md "MATLAB .mat").
/// Atomic, and nothing is written if anything fails.
void write_rendered(const std::string& path, const Document& doc, const Surface& surface, const std::vector<double>& map,
                    const std::vector<double>& frequencies_cpm, std::vector<PendingFile> extra = {},
                    mat::MatVersion mat_version = mat::MatVersion::v5);

/// Renders `surface` into `path`: .bin, .csv and .npy stream chunk by chunk
/// through the library's write_map (memory bounded whatever the length);
/// every other format renders the whole map and goes through
/// write_rendered. `extra` files are committed after the main one (which is
/// taken back if they fail). Returns the mean amplitude of the map.
double write_surface(const std::string& path, const Document& doc, const Surface& surface, std::vector<PendingFile> extra = {},
                     mat::MatVersion mat_version = mat::MatVersion::v5);

/// True for a .mat output path (handled beside OutputKind: a MATLAB file is
/// written by libmatio, not as bytes).
bool is_mat_output(const std::string& path);

/// Rejects, before any work, an output path write_rendered() cannot write
/// (unknown extension) or cannot create. Throws InvalidArgument / IoError.
void check_render_output(const std::string& path);

/// The variables of a rendered map's .mat file: amplitude, position_mm,
/// params, texels (when the surface has Texel regions) and document.
std::vector<mat::Variable> map_variables(const Document& doc, const Surface& surface, const std::vector<double>& map);

/// Texel frequencies of every Texel region (for histograms and summaries).
std::vector<double> texel_frequencies(const Surface& surface);

}  // namespace texel::cli
