// What the parts of the figure layer share beyond drawing.hpp: the size
// limits and checks (validate.cpp), a panel's first-pass plan (layout.cpp),
// line decimation (decimate.cpp) and the axes, colour bar and legend
// (axes_legend.cpp), which plot.cpp calls as it lays out and draws a figure.
// Internal to texel_plot; not installed.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "drawing.hpp"

namespace texel::plot_detail {

inline constexpr int min_side_px = 64;
inline constexpr int max_side_px = 16384;
// 64 Mpx ≈ 256 MB of ARGB: beyond that an atlas is a mistake, not a plot.
inline constexpr double max_area_px = 64.0 * 1024 * 1024;

// ---------------------------------------------------------------- validate.cpp

/// "what[i]": an element's name in an error message.
std::string where(std::string_view what, std::size_t i);

/// Throws InvalidArgument naming the first out-of-range field of the figure
/// (sizes, fonts, every panel and series), `name` being the figure's name.
void check_figure(const Figure& f, const std::string& name);

// ---------------------------------------------------------------- decimate.cpp

/// Pixel-space vertices of the line, NaN x marking a break; long sorted
/// series reduced per pixel column (M4).
Vertices line_vertices(const LineSeries& s, const Scale& xs, const Scale& ys);

// ------------------------------------------------------------------ layout.cpp

/// First pass over a panel: ranges (and category labels, heatmap scale),
/// series colours, then ticks and the margins their labels need.
void plan_ranges(PanelPlan& pp);
void plan_colours(PanelPlan& pp);
void plan_margins(PanelPlan& pp, const Painter& pa, const Fonts& f);

// ------------------------------------------------------------- axes_legend.cpp

/// Second pass, once the plot area is placed: grid, ticks, labels and frame;
/// the heatmap's colour bar; the legend in the emptiest corner.
void draw_axes(const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs, const Scale& ys);
void draw_colour_bar(const PanelPlan& pp, const Painter& pa, const Fonts& f);
void draw_legend(const PanelPlan& pp, const Painter& pa, const Fonts& f, const Scale& xs, const Scale& ys,
                 const std::vector<Vertices>& line_px);

}  // namespace texel::plot_detail
