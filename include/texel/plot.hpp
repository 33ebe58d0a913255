// Plots researchers draw of a texture, rendered with Cairo to PNG or SVG
// (chosen by the output's extension).
//
// Two layers. The figure layer (Figure, Panel, the series types,
// save_figure) is a small general plotting API shared by every command that
// draws: texture maps, spectra, finger swipes. The convenience layer
// (plot_map, plot_map_grid) builds Figures for the plots Texel draws most
// often, so a new kind of plot is a function returning a Figure, never a new
// renderer.
//
// Trade-off: a deliberately small, matplotlib-flavoured subset drawn with
// Cairo's "toy" text API (fontconfig's "sans-serif", no text shaping, no
// superscripts) in exchange for one dependency and no layout engine. Long
// series are decimated to a min/max envelope per pixel column before
// stroking, so a million-point map draws in milliseconds and looks the same
// as the undecimated line at the output resolution.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "texel/units.hpp"

namespace texel {

// ---------------------------------------------------------------- figure layer

/// An sRGB colour, each component in 0 … 1.
struct Rgb {
  double r = 0.0;
  double g = 0.0;
  double b = 0.0;
};

/// The i-th colour of Texel's categorical palette (Tableau 10, chosen for
/// being distinguishable in print and by most colour-blind readers); wraps
/// after 10.
Rgb palette_colour(std::size_t i);

enum class AxisScale { linear, log10 };

/// One axis of a panel. Ranges are in data units; an unset end is taken from
/// the data (with a small margin, except where bars or stems start at 0).
struct Axis {
  std::string label;                    ///< e.g. "position (mm)"; empty = none
  AxisScale scale = AxisScale::linear;  ///< log10: data <= 0 is not drawn
  std::optional<double> min;            ///< lower end (data units); log10: > 0
  std::optional<double> max;            ///< upper end (data units); > min
  /// Log axes of spatial frequency in cycles/mm: each tick also states its
  /// value in dB re 1 cycle/mm (10·log10 f), as a second line "(10 dB)" under
  /// x tick labels or "1 (0 dB)" on y. Ignored on linear axes.
  bool db_labels = false;
  /// A category axis when non-empty: category i sits at data value i, major
  /// ticks at 0 … n − 1 carry these texts (thinned if they would overlap),
  /// and an unset range is −0.5 … n − 0.5. Linear scale only. A heatmap's
  /// row/column labels are used when this is empty.
  std::vector<std::string> categories{};
};

/// A polyline through (x[i], y[i]). x should be sorted ascending: sorted
/// series are clipped to the visible range by binary search and decimated
/// per pixel column; unsorted ones are drawn point by point (slower, same
/// picture). A non-finite y breaks the line.
struct LineSeries {
  std::vector<double> x;      ///< data units of the panel's x axis
  std::vector<double> y;      ///< same length as x
  std::optional<Rgb> colour;  ///< unset: the panel's next palette colour
  double width_px = 1.25;     ///< stroke width, px (0.1 … 20)
  std::string label;          ///< legend text; empty = not in the legend
  bool dashed = false;        ///< dashed stroke (reference lines, e.g. y = x)
};

/// Markers at (x[i], y[i]), optionally on stems from `baseline` (peak lists);
/// with stems = false, a scatter plot.
struct StemSeries {
  std::vector<double> x;          ///< data units
  std::vector<double> y;          ///< same length as x
  std::optional<Rgb> colour;      ///< unset: the panel's next palette colour
  double baseline = 0.0;          ///< stem foot, y data units (log y: clamped to the axis)
  bool stems = true;              ///< false: markers only
  double marker_radius_px = 3.0;  ///< 0 … 20 px; 0 = stems only
  std::string label;              ///< legend text; empty = not in the legend
};

/// Pre-binned counts drawn as bars; bins need not be equally wide (on a log
/// axis equal-width-in-log bins look equal). See make_histogram.
struct Histogram {
  std::vector<double> edges;   ///< counts.size() + 1 ascending bin edges, x data units
  std::vector<double> counts;  ///< one per bin, >= 0
  std::optional<Rgb> colour;   ///< unset: the panel's next palette colour
  std::string label;           ///< legend text; empty = not in the legend
};

/// A labelled vertical line across the plot area (e.g. "central pitch").
struct VerticalMarker {
  double x = 0.0;     ///< x data units; outside the axis range: not drawn
  std::string label;  ///< drawn at the top of the line; empty = none
  Rgb colour{0.25, 0.25, 0.25};
  bool dashed = true;
};

/// Tukey's box-and-whisker summary of one sample (Tukey 1977): quartiles
/// (Hyndman & Fan type 7, R's default), whiskers at the most extreme values
/// within 1.5 IQR of the box, and the values beyond them as outliers.
struct BoxStats {
  std::size_t n = 0;  ///< finite values; 0 = every other field NaN, no outliers
  double q1 = 0, median = 0, q3 = 0;
  double whisker_low = 0, whisker_high = 0;
  double mean = 0;
  std::vector<double> outliers;  ///< ascending
};
/// The box summary of the finite values of `values`.
BoxStats box_stats(std::span<const double> values);

/// Box plots, one per group (categories on x): box q1 … q3 with the median,
/// whiskers, outliers as open circles, the mean as a small cross.
struct BoxSeries {
  std::vector<std::vector<double>> groups;  ///< one sample per box (NaNs skipped; empty = no box)
  std::vector<double> positions;            ///< x of each box, data units; empty = 0, 1, 2 … (a category axis)
  double offset = 0.0;                      ///< added to every position, data units (boxes side by side)
  double box_width = 0.5;                   ///< data units, > 0
  std::optional<Rgb> colour;                ///< unset: the panel's next palette colour
  bool show_mean = true;                    ///< mark the mean with a cross
  bool show_points = false;                 ///< every value as a small dot over its box
  std::string label;                        ///< legend text; empty = not in the legend
};

/// Points with symmetric error bars (mean ± SEM, mean ± CI half-width),
/// optionally joined by a line in x order.
struct ErrorBarSeries {
  std::vector<double> x;          ///< data units
  std::vector<double> y;          ///< same length as x
  std::vector<double> error;      ///< half-length of each bar, >= 0 (NaN = no bar); same length as x
  std::optional<Rgb> colour;      ///< unset: the panel's next palette colour
  bool connect = false;           ///< join the points with a line
  double marker_radius_px = 3.5;  ///< 0 … 20 px
  double cap_px = 5.0;            ///< half-width of the bar caps, 0 … 40 px
  std::string label;              ///< legend text; empty = not in the legend
};

/// A matrix drawn as coloured cells (e.g. a similarity matrix), the value
/// printed in each cell and a colour bar at the right. Row 0 is drawn at the
/// top; cell (r, c) is centred on x = c, y = rows − 1 − r, so the panel's
/// axes become category axes labelled with the row and column labels.
struct HeatmapSeries {
  std::size_t rows = 0;
  std::size_t cols = 0;
  std::vector<double> values;              ///< rows × cols, row-major; NaN = blank cell
  std::vector<std::string> row_labels;     ///< rows texts, or empty
  std::vector<std::string> column_labels;  ///< cols texts, or empty
  std::optional<double> min;               ///< colour-scale end; unset = data minimum
  std::optional<double> max;               ///< colour-scale end; unset = data maximum
  int decimals = 1;                        ///< digits of the printed values, 0 … 6; −1 = no text
  std::string scale_label;                 ///< colour bar label, e.g. "mean rating (1–5)"
};

/// Text placed at a data point (a p value over a bar, a name by an ellipse).
struct TextNote {
  double x = 0.0;  ///< data units: where the text is centred
  double y = 0.0;  ///< data units: the text's vertical middle
  std::string text;
  Rgb colour{0.1, 0.1, 0.1};
  double dy_px = 0.0;  ///< shift after placing, px (negative = up), e.g. to sit just above a point
};

/// One plot area with its axes, series and legend. Draw order, back to
/// front: grid, heatmap, histograms, markers, boxes, lines, error bars,
/// stems, notes; palette colours are assigned in the order lines, stems,
/// histograms, boxes, error bars.
struct Panel {
  std::string title;  ///< above the plot area; empty = none
  Axis x;
  Axis y;
  std::vector<LineSeries> lines;
  std::vector<StemSeries> stems;
  std::vector<Histogram> histograms;
  std::vector<VerticalMarker> markers;
  std::vector<BoxSeries> boxes;
  std::vector<ErrorBarSeries> error_bars;
  std::optional<HeatmapSeries> heatmap;  ///< at most one matrix per panel
  std::vector<TextNote> notes;
  bool legend = true;          ///< drawn (top right) when more than one series is labelled
  double height_weight = 1.0;  ///< relative height of this panel's row (> 0)
};

/// A figure: `panels` laid out row-major in `columns` columns, rows sharing
/// the height by their panels' height_weight. Plot areas in one column share
/// their left edge and those in one row their top and bottom, so stacked
/// panels line up.
struct Figure {
  int width_px = 1000;    ///< 64 … 16384 px (SVG: CSS px)
  int height_px = 700;    ///< 64 … 16384 px
  std::string title;      ///< above all panels; empty = none
  int columns = 1;        ///< >= 1
  double font_px = 13.0;  ///< base text size, 4 … 72 px; titles are larger, ticks smaller
  std::vector<Panel> panels;
};

/// Several figures drawn side by side in one image (an atlas / overview),
/// row-major in `columns` columns. Every cell is as large as the largest
/// figure; a smaller one is centred in its cell.
struct FigureGrid {
  std::string title;      ///< above all cells; empty = none
  int columns = 3;        ///< >= 1
  double font_px = 16.0;  ///< size of `title`, px
  std::vector<Figure> cells;
};

enum class PlotFormat { png, svg };

/// The format named by `path`'s extension, case-insensitive (".png", ".svg");
/// anything else throws InvalidArgument naming the extension and the allowed ones.
PlotFormat plot_format_for_path(const std::string& path);

/// The encoded image (PNG bytes or SVG text), for front doors that do not
/// write files (the web studio, Python). Throws InvalidArgument for a figure
/// that breaks a documented range, IoError if Cairo fails.
std::string render_figure(const Figure& figure, PlotFormat format);
std::string render_figure_grid(const FigureGrid& grid, PlotFormat format);

/// Renders and writes to `path` (.png or .svg) atomically: a temporary in the
/// same directory renamed over `path`, so on failure no file is left.
/// Throws InvalidArgument (bad extension or figure) or IoError (unwritable).
void save_figure(const Figure& figure, const std::string& path);
void save_figure_grid(const FigureGrid& grid, const std::string& path);

/// A tick mark. Major ticks carry a label (possibly thinned when drawn, if
/// labels would overlap) and a grid line; minor ones are short marks only.
struct Tick {
  double value = 0.0;     ///< data units
  std::string label;      ///< empty for minor ticks
  std::string secondary;  ///< db_labels: "(10 dB)"; else empty
  bool major = true;
};

/// Ticks for [min, max]. Linear: 1-2-5 steps, about `target` of them. Log:
/// one per decade (every n-th decade beyond ~`target` decades) with unlabelled
/// minor ticks at 2 … 9; spans under about 1.5 decades also label 2 and 5,
/// and spans with no power of ten inside fall back to 1-2-5 steps.
/// Throws InvalidArgument if min >= max, either is not finite, or log min <= 0.
std::vector<Tick> axis_ticks(double min, double max, AxisScale scale, bool db_labels = false, int target = 6);

/// Bins the finite values (and, for log10, the positive ones) into `bins`
/// bins of equal width on `scale` between their min and max; bins == 0 picks
/// 2·n^(1/3) clamped to 5 … 80 (Rice rule). No usable value: empty histogram.
/// Throws InvalidArgument if bins > 100000.
Histogram make_histogram(std::span<const double> values, std::size_t bins = 0, AxisScale scale = AxisScale::linear);

// ------------------------------------------------------------ texture plots

/// A friction map and, optionally, the texel frequencies it was drawn from.
struct MapPlot {
  std::string title;                    ///< figure title; empty = "Friction map"
  std::vector<double> positions_mm;     ///< x of each sample (mm), ascending
  std::vector<double> amplitudes;       ///< a in [0, 1] of each sample
  std::vector<double> frequencies_cpm;  ///< texel frequencies for the histogram (cycles/mm; may be empty)
  Millimetres excerpt{6.0};             ///< length of the zoomed excerpt from the first sample; 0 = none
  CyclesPerMm central_pitch{0.0};       ///< > 0: marked on the histogram
  int width_px = 1000;                  ///< plot_map image width, px
  int height_px = 0;                    ///< plot_map image height, px; 0 = 260 per panel
};

/// The full map figure: the whole map on top, the excerpt in the middle (if
/// excerpt_mm > 0 and shorter than the map), and a histogram of texel
/// frequencies on a log axis at the bottom (if any are given), ticks in
/// cycles/mm with dB re 1 cycle/mm in parentheses below each, and the central
/// pitch marked. Throws InvalidArgument if positions and amplitudes are empty
/// or differ in length.
Figure map_figure(const MapPlot& plot);

/// A compact figure for one cell of an atlas: title, the excerpt, and the
/// frequency histogram (if any), at `width_px` × `height_px`.
Figure map_cell_figure(const MapPlot& plot, int width_px = 440, int height_px = 380);

/// Draws map_figure(plot) to `path` (.png or .svg), atomically.
void plot_map(const MapPlot& plot, const std::string& path);

/// Draws an atlas of map_cell_figure cells, `columns` per row, to `path`
/// (.png or .svg), atomically; `title` above all cells (empty = none).
void plot_map_grid(std::span<const MapPlot> plots, const std::string& path, int columns = 3, const std::string& title = {});

}  // namespace texel
