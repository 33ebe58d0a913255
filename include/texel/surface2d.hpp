// The 2-D model (docs/algorithm.md §11): a Texel texture laid out in the
// plane for 2-D touch surfaces and friction bitmaps.
//
// A FineField2D is the fine oscillation s(x, y) in [−1, 1] of one texture on
// the infinite plane, in one of four designs (Field2D): a stationary
// isotropic field whose radial spectrum is the best non-negative one for the
// 1-D texture's Central Pitch and Irregularity through the Abel relation
// (isotropic_bound) — as 256 plane waves (spectral, version 4's default) or
// as periodic tiles synthesised by an inverse FFT and interpolated by cubic
// B-splines (tile, version 5's default) — texel cells in random
// orientations, or an oriented grating. A CoarseField2D is a 2-D coarse profile
// c(x, y) in [0, 1]. A Surface2D puts them in a document's regions and mixes
// them exactly as the 1-D texels are mixed (texel_mix, §7): every pixel is a
// pure function of its (x, y), so tiles, strips and threads never change a
// bit. Everything is computed with texel::detmath and texel::CounterRng, so
// the bytes are the same on every build (§9).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "texel/distribution.hpp"
#include "texel/document.hpp"
#include "texel/raster2d.hpp"
#include "texel/surface2d_spec.hpp"

namespace texel {

/// The fine field of one texture, on the plane (texture coordinates, mm).
/// Immutable once built; value() is safe to call from several threads.
class FineField2D {
 public:
  /// `band_top`: the highest spatial frequency any straight scan may carry
  /// (for a bitmap, its pixel grid's Nyquist frequency). Validates `spec`.
  FineField2D(const TexelSpec& spec, Field2D design, double orientation_deg, CyclesPerMm band_top);

  /// s(x, y) in [−1, 1].
  [[nodiscard]] double value(double x_mm, double y_mm) const;
  /// out[k] = value((first + k)·pitch − origin_x, y): a run of a raster row
  /// whose pixel i sits at i·pitch, in texture coordinates.
  void row(std::int64_t first, double pitch_mm, double origin_x_mm, double y_mm, std::span<double> out) const;
  /// out[i] = value(xs[i], ys[i]), the spectral design several points at a
  /// time (the same bits as value()). Throws InvalidArgument if the sizes differ.
  void values(std::span<const double> xs, std::span<const double> ys, std::span<double> out) const;
  /// A block of rows: out[r·stride + k] = value((first + k)·pitch − origin_x,
  /// ys[r]), the same values row() gives, computed a tile at a time
  /// (the spectral design's plane waves split into x and y factors once per
  /// block).
  void block(std::int64_t first, std::size_t count, double pitch_mm, double origin_x_mm, std::span<const double> ys, double* out,
             std::size_t stride) const;
  /// Oriented fields are defined for |x|, |y| up to this (mm); at rest beyond.
  static constexpr double oriented_extent_mm = 2000.0;

  [[nodiscard]] Field2D design() const { return design_; }
  /// Spectral design: the radial spectrum's components (frequency cpm,
  /// direction in cycles of a full turn), for inspection and tests.
  struct Component {
    double frequency = 0.0;
    double cos_dir = 1.0, sin_dir = 0.0;
    double phase = 0.0;
  };
  [[nodiscard]] const std::vector<Component>& components() const { return components_; }
  /// Components of the spectral design (the sum is scaled to an RMS of 1/3
  /// and clipped to [−1, 1]).
  static constexpr int spectral_components = 256;

  /// Tile design: one periodic tile per band of radial frequencies (an
  /// octave-like band of ratio tile_band_ratio, the highest first), N × N
  /// samples (tile_samples) h apart, period N·h; s is the sum over the
  /// bands of each tile's cubic B-spline, clipped to [−1, 1].
  struct TileBand {
    double spacing_mm = 0.0;        ///< h
    double q_lo = 0.0, q_hi = 0.0;  ///< the band's radial frequencies (cpm), q_lo ≤ |q| < q_hi
    std::size_t modes = 0;          ///< lattice frequencies with power
    [[nodiscard]] double period_mm() const { return spacing_mm * static_cast<double>(tile_samples); }
  };
  [[nodiscard]] std::vector<TileBand> tile_bands() const;
  static constexpr int tile_samples = 1024;
  static constexpr double tile_band_ratio = 16.0;
  /// Samples per cycle of a band's highest frequency.
  static constexpr double tile_oversampling = 4.0;

 private:
  struct Cell {
    double frequency, cos_dir, sin_dir, phase;
  };
  [[nodiscard]] Cell cell(std::int64_t m, std::int64_t n) const;

  TexelSpec spec_;
  Field2D design_;
  double cos_n_ = 1.0, sin_n_ = 0.0;                // oriented: the grating's direction
  std::shared_ptr<const class TexelTexture> line_;  // oriented: the 1-D texture along n
  double line_origin_ = 0.0;                        // oriented: projection offset (mm)
  std::unique_ptr<PitchDistribution> cells_;        // cells: the corrected distribution
  std::vector<Component> components_;               // spectral
  double spectral_gain_ = 0.0;
  struct Tile {
    TileBand band;
    double inv_spacing = 0.0;
    std::vector<float> samples;  // tile_samples rows of tile_samples + 3 (the first 3 repeated)
  };
  std::vector<Tile> tiles_;  // tile
  void build_tiles(const PitchDistribution& line);
  void tile_block(std::int64_t first, std::size_t count, double pitch, double origin_x, std::span<const double> ys, double* out,
                  std::size_t stride) const;
};

/// The cosine law a cell design corrects for: a plane wave of frequency q
/// whose direction is uniform over the half-turn is scanned at q·|cos θ|;
/// 10·log10|cos θ| has mean −10·log10(2) dB and SD π/√12·10/ln 10 dB.
inline constexpr double cosine_law_mean_db = -3.0102999566398120;
inline constexpr double cosine_law_sd_db = 3.9389060279432016;

/// The 2-D coarse profile c(x, y) in [0, 1] (texture coordinates, mm): shapes
/// are evaluated exactly, images (loaded once, from PNG or .npy) bilinearly.
class CoarseField2D {
 public:
  /// `region_width`/`region_height`: the rectangle an image with width or
  /// height 0 stretches over. Loads images; throws IoError / FormatError.
  CoarseField2D(const Coarse2D& spec, Millimetres region_width, Millimetres region_height);
  [[nodiscard]] double value(double x_mm, double y_mm) const;
  /// out[k] = value((first + k)·pitch − origin_x, y).
  void row(std::int64_t first, double pitch_mm, double origin_x_mm, double y_mm, std::span<double> out) const;
  [[nodiscard]] bool constant() const { return constant_; }

 private:
  Coarse2D spec_;
  bool constant_ = false;
  Raster2D image_;  // image profiles: values in [0, 1], origin and pitch placing it
  double image_pitch_y_ = 0.0;
};

/// A prepared 2-D document: every region's fields on the device's bitmap grid.
class Surface2D {
 public:
  struct Region {
    std::string name;
    double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;  ///< the rectangle (device mm)
    TexelSpec texel;
    std::shared_ptr<const FineField2D> fine;
    std::shared_ptr<const CoarseField2D> coarse;
  };

  Surface2D(const BitmapGeometry& geometry, std::vector<Region> regions);
  [[nodiscard]] const BitmapGeometry& geometry() const { return geometry_; }
  [[nodiscard]] const std::vector<Region>& regions() const { return regions_; }

  /// Amplitudes a in [0, 1] of pixel rows [first_row, first_row + rows),
  /// row-major into `out` (rows × width values); 0 outside every region.
  /// Any strip gives the whole bitmap's values.
  void render_rows(int first_row, int rows, std::span<double> out) const;
  /// The amplitude at a point of the surface (device mm): exactly the value
  /// render_rows gives a pixel sitting there.
  [[nodiscard]] double amplitude(double x_mm, double y_mm) const;

 private:
  BitmapGeometry geometry_;
  std::vector<Region> regions_;
};

/// Prepares a 2-D document (doc.surface2d set; InvalidArgument otherwise):
/// its fields are limited to the bitmap grid's Nyquist frequency.
Surface2D prepare_surface2d(const Document& doc);

/// The document's coarse profile c(x, y) of region `region` sampled on the
/// device's bitmap grid (values in [0, 1]; 0 outside the region), for the
/// 2-D player; `pitch` (> 0) samples it on another square grid over the
/// same surface. The region's coarse and fine strengths mix it with a fine
/// oscillation as texel_mix does.
Raster2D coarse_raster(const Document& doc, std::size_t region = 0, Millimetres pitch = Millimetres(0.0));
/// The whole bitmap's amplitudes (float) as a Raster2D: the friction map the
/// document renders to, before polarity and quantisation. Allocates
/// width·height floats: large maps go through write_bitmap instead.
Raster2D render_raster(const Surface2D& surface);

/// The pixel a friction bitmap stores for amplitude a (docs/format.md
/// "Friction bitmaps"): a clamped to [0, 1], taken as 1 − a for a device of
/// polarity brighter_more_friction, then round(a·255) for depth 8 or
/// to_u16(a) (round(a·65535)) for depth 16. The one rule of write_bitmap's
/// PNG pixels and of render_pixel_rows.
inline std::uint16_t bitmap_pixel(double a, BitmapPolarity polarity, int depth) noexcept {
  a = a > 0.0 ? (a < 1.0 ? a : 1.0) : 0.0;  // NaN -> 0
  if (polarity == BitmapPolarity::brighter_more_friction) a = 1.0 - a;
  return depth == 8 ? static_cast<std::uint16_t>(a * 255.0 + 0.5) : to_u16(a);
}
/// Pixel rows [first_row, first_row + rows) as a bitmap of `depth` bits (8
/// or 16; 0 = the device's) stores them: bitmap_pixel of render_rows, row-
/// major into `out` (rows × width). Exactly the pixels write_bitmap puts in
/// a PNG of that depth. Throws InvalidArgument for a bad depth, row range or
/// buffer size.
void render_pixel_rows(const Surface2D& surface, int first_row, int rows, int depth, std::span<std::uint16_t> out);

/// The best a stationary isotropic field can do for a 1-D target: the 1-D
/// texture's lognormal frequency density t(k) (truncated to its band) and the
/// radial spectrum S2 ≥ 0 whose straight scans S1 = A·S2 (the Abel relation,
/// S1(k) = 2∫_k^∞ S2(q)·q/√(q² − k²) dq, exact for piecewise-constant S2)
/// are closest to it in relative (log-spectral) terms, on a log-frequency grid.
///
/// Two fits are made. `radial`/`scan`: the log-spectral-shape fit above.
/// `matched_radial`/`matched_scan`: the moment fit — the power-weighted
/// log-frequency moments (what Central Pitch and Irregularity measure) of a
/// scan are the radial spectrum's moments convolved with the cosine law's,
/// mean −3.01 dB and variance 3.94² dB², so S2 lognormal with the 1-D
/// median + 3.01 dB and σ'² = max(σ² − σ_cos², 0) reaches the 1-D Central
/// Pitch exactly and the Irregularity max(I_1D, 3.94 dB): the best any
/// non-negative S2 can do in those two measures.
struct IsotropicBound {
  std::vector<double> frequency;       ///< k = q grid (cpm), log-spaced
  std::vector<double> target;          ///< t(k), density per cpm (unit area)
  std::vector<double> radial;          ///< S2 on [q_j, q_j+1) (≥ 0), log-spectral fit
  std::vector<double> scan;            ///< A·S2: what straight scans carry
  std::vector<double> matched_radial;  ///< S2 of the moment fit
  std::vector<double> matched_scan;    ///< its A·S2
  double target_log_centroid_db = 0.0, target_log_spread_db = 0.0;
  double scan_log_centroid_db = 0.0, scan_log_spread_db = 0.0;
  double matched_log_centroid_db = 0.0, matched_log_spread_db = 0.0;
};
IsotropicBound isotropic_bound(const PitchDistribution& distribution, CyclesPerMm band_top);
/// The moment fit's radial frequency distribution for a 1-D distribution.
PitchDistribution cosine_corrected(const PitchDistribution& line);

/// Straight scans of a field analysed with the 1-D spectrum tools
/// (texel/spectrum.hpp): per direction, `scans` parallel lines of `samples`
/// points `spacing` apart, their power spectra averaged, then the power-
/// weighted log-frequency centroid (Central Pitch as the tools measure it)
/// and log spread (Irregularity) over the whole band.
struct ScanOptions {
  int directions = 36;  ///< 0°, 180°/directions, … (0° … 175° for 36)
  int scans = 8;
  std::size_t samples = 4096;
  Millimetres spacing{0.0053};
};
struct DirectionStats {
  double direction_deg = 0.0;
  double log_centroid_db = 0.0;
  double log_spread_db = 0.0;
};
std::vector<DirectionStats> measure_scans(const FineField2D& field, const ScanOptions& options);
/// The same analysis of the 1-D texture itself (windows of the same length).
DirectionStats measure_line(const TexelSpec& spec, CyclesPerMm band_top, const ScanOptions& options);

}  // namespace texel
