// The drawing parts the figure layer (plot.cpp and its parts: layout.cpp,
// axes_legend.cpp, ticks.cpp, …) shares with the series painters (series.cpp): Cairo itself
// (opened on first use), the Cairo painter, the data-to-pixel scale and a
// panel's plan. Internal to texel_plot; not installed.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <cairo-svg.h>
#include <cairo.h>

#include "texel/detail/format.hpp"
#include "texel/detail/shared_object.hpp"
#include "texel/plot.hpp"

#ifndef TEXEL_CAIRO_SONAME
#error "TEXEL_CAIRO_SONAME (Cairo's shared object name) is set by src/CMakeLists.txt"
#endif

namespace texel::plot_detail {

// Cairo is opened on first use (dlopen), not linked: with X11, fontconfig,
// FreeType and pixman it is some twenty libraries that every texel command
// would otherwise load at start-up, though only figures need it. <cairo.h>
// and <cairo-svg.h> still give the types and constants.
// clang-format off
#define TEXEL_CAIRO_FUNCTIONS(X) \
  X(cairo_arc) \
  X(cairo_clip) \
  X(cairo_create) \
  X(cairo_destroy) \
  X(cairo_fill) \
  X(cairo_fill_preserve) \
  X(cairo_font_extents) \
  X(cairo_font_options_create) \
  X(cairo_font_options_destroy) \
  X(cairo_font_options_set_antialias) \
  X(cairo_font_options_set_hint_metrics) \
  X(cairo_font_options_set_hint_style) \
  X(cairo_image_surface_create) \
  X(cairo_line_to) \
  X(cairo_move_to) \
  X(cairo_new_sub_path) \
  X(cairo_paint) \
  X(cairo_rectangle) \
  X(cairo_restore) \
  X(cairo_rotate) \
  X(cairo_save) \
  X(cairo_select_font_face) \
  X(cairo_set_antialias) \
  X(cairo_set_dash) \
  X(cairo_set_font_options) \
  X(cairo_set_font_size) \
  X(cairo_set_line_cap) \
  X(cairo_set_line_join) \
  X(cairo_set_line_width) \
  X(cairo_set_source_rgb) \
  X(cairo_set_source_rgba) \
  X(cairo_show_text) \
  X(cairo_status) \
  X(cairo_status_to_string) \
  X(cairo_stroke) \
  X(cairo_surface_destroy) \
  X(cairo_surface_finish) \
  X(cairo_surface_flush) \
  X(cairo_surface_status) \
  X(cairo_surface_write_to_png_stream) \
  X(cairo_svg_surface_create_for_stream) \
  X(cairo_svg_surface_set_document_unit) \
  X(cairo_text_extents) \
  X(cairo_translate)
// clang-format on

/// Cairo, opened when the first figure is drawn (`cairo()`); without it the
/// rest of Texel works and a figure is an IoError naming the library.
TEXEL_SHARED_LIBRARY(Cairo, cairo, TEXEL_CAIRO_SONAME, "figures (PNG, SVG)", TEXEL_CAIRO_FUNCTIONS)

inline constexpr double nan = std::numeric_limits<double>::quiet_NaN();

/// Replaces a leading '-' by U+2212 (typographic minus), which lines up with '+'.
inline std::string typographic(std::string s) {
  if (!s.empty() && s[0] == '-') s.replace(0, 1, "\u2212");
  return s;
}

struct Rect {
  double x = 0, y = 0, w = 0, h = 0;
  [[nodiscard]] double right() const { return x + w; }
  [[nodiscard]] double bottom() const { return y + h; }
};

enum class HAlign { left, centre, right };
enum class VAlign { top, middle, bottom };

/// dB re 1 cycle/mm of f (power form, docs/algorithm.md §2), rounded for a label.
inline std::string db_text(double f) {
  const double db = 10.0 * std::log10(f);
  const double rounded = std::round(db);
  const std::string s = std::abs(db - rounded) < 0.05 ? detail::fixed(rounded == 0.0 ? 0.0 : rounded, 0) : detail::fixed(db, 1);
  return typographic(s) + " dB";
}

inline const Rgb text_colour{0.1, 0.1, 0.1};
inline const Rgb muted_colour{0.38, 0.38, 0.38};
inline const Rgb frame_colour{0.3, 0.3, 0.3};
inline const Rgb grid_colour{0.88, 0.88, 0.88};

/// Thin wrapper over a cairo_t: colours, text with alignment, measurement.
class Painter {
 public:
  explicit Painter(cairo_t* cr) : cr_(cr) {
    cairo_font_options_t* opts = cairo().cairo_font_options_create();
    // Unhinted metrics: text measures the same in PNG and SVG.
    cairo().cairo_font_options_set_hint_metrics(opts, CAIRO_HINT_METRICS_OFF);
    cairo().cairo_font_options_set_hint_style(opts, CAIRO_HINT_STYLE_SLIGHT);
    cairo().cairo_font_options_set_antialias(opts, CAIRO_ANTIALIAS_GRAY);
    cairo().cairo_set_font_options(cr_, opts);
    cairo().cairo_font_options_destroy(opts);
    cairo().cairo_set_antialias(cr_, CAIRO_ANTIALIAS_DEFAULT);
  }
  [[nodiscard]] cairo_t* cr() const { return cr_; }

  void colour(Rgb c, double alpha = 1.0) const { cairo().cairo_set_source_rgba(cr_, c.r, c.g, c.b, alpha); }

  void font(double size_px, bool bold = false) const {
    cairo().cairo_select_font_face(cr_, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                                   bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo().cairo_set_font_size(cr_, size_px);
  }
  /// Advance width of `s` in the current font, px.
  [[nodiscard]] double width(const std::string& s) const {
    if (s.empty()) return 0.0;
    cairo_text_extents_t e;
    cairo().cairo_text_extents(cr_, s.c_str(), &e);
    return e.x_advance;
  }
  /// Line height of the current font, px.
  [[nodiscard]] double line_height() const {
    cairo_font_extents_t e;
    cairo().cairo_font_extents(cr_, &e);
    return e.height;
  }
  /// Draws `s` anchored at (x, y), rotated by `angle` radians about the anchor.
  /// Vertical alignment uses the font's ascent/descent, not the glyphs', so
  /// labels with and without descenders share a baseline.
  void text(const std::string& s, double x, double y, HAlign h, VAlign v, double angle = 0.0) const {
    if (s.empty()) return;
    cairo_font_extents_t fe;
    cairo().cairo_font_extents(cr_, &fe);
    const double w = width(s);
    const double dx = h == HAlign::left ? 0.0 : h == HAlign::centre ? -w / 2 : -w;
    const double dy = v == VAlign::top ? fe.ascent : v == VAlign::middle ? (fe.ascent - fe.descent) / 2 : -fe.descent;
    cairo().cairo_save(cr_);
    cairo().cairo_translate(cr_, x, y);
    if (angle != 0.0) cairo().cairo_rotate(cr_, angle);
    cairo().cairo_move_to(cr_, dx, dy);
    cairo().cairo_show_text(cr_, s.c_str());
    cairo().cairo_restore(cr_);
  }
  void rect(const Rect& r) const { cairo().cairo_rectangle(cr_, r.x, r.y, r.w, r.h); }

  /// `s` fitted into `max_w` px: the font shrinks down to 70 % of `size_px`,
  /// then the text is cut with an ellipsis. Selects the font it fits with.
  [[nodiscard]] std::string fit(std::string s, double max_w, double size_px, bool bold) const {
    font(size_px, bold);
    const double w = width(s);
    if (w <= max_w) return s;
    const double shrunk = std::max(size_px * 0.7, size_px * max_w / w);
    font(shrunk, bold);
    // Cut whole UTF-8 characters (continuation bytes, then the lead byte).
    while (!s.empty() && width(s + "\u2026") > max_w) {
      while (!s.empty() && (static_cast<unsigned char>(s.back()) & 0xC0) == 0x80) s.pop_back();
      if (!s.empty()) s.pop_back();
    }
    return s + "\u2026";
  }

 private:
  cairo_t* cr_;
};

/// Maps data to pixels along one axis.
struct Scale {
  double lo = 0, hi = 1;  // data range
  double p0 = 0, p1 = 1;  // pixel positions of lo and hi
  bool log = false;
  double l0 = 0, l1 = 1;

  Scale() = default;
  Scale(double lo_, double hi_, double p0_, double p1_, bool log_) : lo(lo_), hi(hi_), p0(p0_), p1(p1_), log(log_) {
    l0 = log ? std::log10(lo) : lo;
    l1 = log ? std::log10(hi) : hi;
  }
  /// Pixel position of v; NaN where v cannot be drawn (log of v <= 0, NaN).
  [[nodiscard]] double operator()(double v) const {
    if (log) {
      if (!(v > 0)) return nan;
      v = std::log10(v);
    }
    if (!std::isfinite(v)) return nan;
    return p0 + (v - l0) / (l1 - l0) * (p1 - p0);
  }
};

struct Swatch {
  enum Kind { line, stem, bar } kind;
  Rgb colour;
  std::string label;
};

/// Everything about a panel that is known before it is placed.
struct PanelPlan {
  const Panel* panel = nullptr;
  Rect cell;  // the panel's share of the figure
  double xlo = 0, xhi = 1, ylo = 0, yhi = 1;
  std::vector<Tick> xticks, yticks;
  std::vector<Rgb> line_colours, stem_colours, hist_colours, box_colours, error_colours;
  std::vector<std::vector<BoxStats>> boxes;
  std::vector<std::string> xcats, ycats;            // category labels in effect (axis or heatmap)
  double heat_lo = 0, heat_hi = 1;                  // colour-scale range of the heatmap
  double colour_bar = 0;                            // px reserved right of the plot for the heatmap's colour bar
  double left = 0, right = 0, top = 0, bottom = 0;  // margins, px
  Rect plot;
};

inline constexpr double colour_bar_px = 12.0;  // width of a heatmap's colour bar

/// A heatmap value as printed in its cell and on the colour bar.
inline std::string format_heat(double v, const HeatmapSeries& h) {
  return typographic(detail::fixed(v, std::max(0, h.decimals)));
}

/// ColorBrewer "Blues" (Brewer 2003; sequential, print- and colour-blind-safe)
/// at t in [0, 1], interpolated linearly between its nine classes.
inline Rgb blues(double t) {
  static constexpr Rgb stops[] = {{0.969, 0.984, 1.000}, {0.871, 0.922, 0.969}, {0.776, 0.859, 0.937},
                                  {0.620, 0.792, 0.882}, {0.420, 0.682, 0.839}, {0.259, 0.573, 0.776},
                                  {0.129, 0.443, 0.710}, {0.031, 0.318, 0.612}, {0.031, 0.188, 0.420}};
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 8.0;
  const auto i = std::min<std::size_t>(7, static_cast<std::size_t>(t));
  const double u = t - static_cast<double>(i);
  const Rgb a = stops[i], b = stops[i + 1];
  return {a.r + (b.r - a.r) * u, a.g + (b.g - a.g) * u, a.b + (b.b - a.b) * u};
}

struct Fonts {
  double base, title, tick, small;
  explicit Fonts(double b) : base(b), title(b * 1.12), tick(b * 0.88), small(b * 0.82) {}
};

/// x of box group `g` of series `b`.
inline double box_x(const BoxSeries& b, std::size_t g) {
  return (b.positions.empty() ? static_cast<double>(g) : b.positions[g]) + b.offset;
}

/// Pixel-space vertices of a polyline, NaN x marking a break.
using Vertices = std::vector<std::pair<double, double>>;

/// Where a vertical marker's label goes: right of the line at the top of the
/// plot, or left of it where there is no room on the right.
inline Rect marker_label_box(const VerticalMarker& m, double x, const Rect& r, const Painter& pa, const Fonts& f) {
  pa.font(f.small);
  const double w = pa.width(m.label), h = pa.line_height();
  const bool left = x + 4 + w > r.right() - 2;
  return {left ? x - 4 - w : x + 4, r.y + 4, w, h};
}

/// Draws every series of the panel into its plot area, clipped to it, in a
/// fixed order (heatmap, histograms, markers, boxes, lines, error bars,
/// stems, notes): later series are drawn over earlier ones.
void draw_series(const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs, const Scale& ys,
                 const std::vector<Vertices>& line_px);

}  // namespace texel::plot_detail
