// Statistical series of the plot library (the perceptual studies' figures):
// Tukey box statistics against hand-computed values, box plots, error bars,
// heatmaps with their colour bar, category axes, dashed lines and notes all
// render to PNG and SVG, what they draw is where it should be (decoded PNG
// pixels), and every malformed series is rejected with InvalidArgument.
#include <gtest/gtest.h>

#include <cairo.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/plot.hpp"

using namespace texel;

namespace {

struct Reader {
  const std::string* bytes;
  std::size_t at = 0;
};

cairo_status_t read_png(void* closure, unsigned char* data, unsigned int length) {
  auto* r = static_cast<Reader*>(closure);
  if (r->at + length > r->bytes->size()) return CAIRO_STATUS_READ_ERROR;
  std::copy_n(r->bytes->data() + r->at, length, data);
  r->at += length;
  return CAIRO_STATUS_SUCCESS;
}

/// Pixels of a PNG within `tol` (per 0 … 255 channel) of `c`.
std::size_t count_colour(const std::string& png, Rgb c, int tol = 6) {
  Reader r{&png};
  cairo_surface_t* s = cairo_image_surface_create_from_png_stream(read_png, &r);
  EXPECT_EQ(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
  const int w = cairo_image_surface_get_width(s), h = cairo_image_surface_get_height(s);
  const int stride = cairo_image_surface_get_stride(s);
  const unsigned char* d = cairo_image_surface_get_data(s);
  const auto near = [&](unsigned v, double want) {
    return std::abs(static_cast<int>(v) - static_cast<int>(std::lround(want * 255))) <= tol;
  };
  std::size_t n = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint32_t px;
      std::memcpy(&px, d + y * stride + x * 4, 4);
      if (near((px >> 16) & 0xff, c.r) && near((px >> 8) & 0xff, c.g) && near(px & 0xff, c.b)) ++n;
    }
  cairo_surface_destroy(s);
  return n;
}

Figure one_panel(Panel p) {
  Figure f;
  f.width_px = 500;
  f.height_px = 400;
  f.panels.push_back(std::move(p));
  return f;
}

Panel box_panel() {
  Panel p;
  p.title = "Convergent texel length";
  p.x = Axis{"distribution", AxisScale::linear, std::nullopt, std::nullopt, false, {"narrow", "wide"}};
  p.y.label = "texel length (mm)";
  p.boxes.push_back(BoxSeries{{{10, 11, 12, 13, 14, 30}, {5, 6, 7, 8}}, {}, 0.0, 0.5, Rgb{0.8, 0.1, 0.1}, true, true, {}});
  return p;
}

const Rgb blues_darkest{0.031, 0.188, 0.420};
const Rgb blues_lightest{0.969, 0.984, 1.000};

}  // namespace

TEST(PlotBoxStats, TukeyFencesAndTypeSevenQuartiles) {
  const std::vector<double> v{9, 1, 2, 3, 4, 5, 6, 7, 8, 100, std::nan("")};
  const BoxStats st = box_stats(v);
  EXPECT_EQ(st.n, 10u);
  // Type 7: h = 9p → q1 = x(3) + 0.25, median = 5.5, q3 = x(7) + 0.75.
  EXPECT_DOUBLE_EQ(st.q1, 3.25);
  EXPECT_DOUBLE_EQ(st.median, 5.5);
  EXPECT_DOUBLE_EQ(st.q3, 7.75);
  // Fences 3.25 − 6.75 = −3.5 and 7.75 + 6.75 = 14.5: only 100 lies outside.
  EXPECT_DOUBLE_EQ(st.whisker_low, 1);
  EXPECT_DOUBLE_EQ(st.whisker_high, 9);
  EXPECT_EQ(st.outliers, std::vector<double>{100});
  EXPECT_DOUBLE_EQ(st.mean, 14.5);
}

TEST(PlotBoxStats, EmptyAndSingleSamples) {
  const BoxStats none = box_stats(std::vector<double>{std::nan("")});
  EXPECT_EQ(none.n, 0u);
  EXPECT_TRUE(std::isnan(none.median));
  const BoxStats one = box_stats(std::vector<double>{4.0});
  EXPECT_EQ(one.n, 1u);
  EXPECT_DOUBLE_EQ(one.q1, 4.0);
  EXPECT_DOUBLE_EQ(one.whisker_high, 4.0);
  EXPECT_TRUE(one.outliers.empty());
}

TEST(PlotStat, BoxPlotRendersBoxesInItsColour) {
  const Figure f = one_panel(box_panel());
  const std::string png = render_figure(f, PlotFormat::png);
  ASSERT_FALSE(png.empty());
  EXPECT_GT(count_colour(png, {0.8, 0.1, 0.1}, 10), 100u);  // box outlines, whiskers, median
  const std::string svg = render_figure(f, PlotFormat::svg);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  // The outlier (30) is drawn: dropping it changes the picture.
  Panel p = box_panel();
  p.boxes[0].groups[0].pop_back();
  p.y.min = 4;
  p.y.max = 32;
  Panel q = box_panel();
  q.y.min = 4;
  q.y.max = 32;
  EXPECT_NE(render_figure(one_panel(p), PlotFormat::png), render_figure(one_panel(q), PlotFormat::png));
}

TEST(PlotStat, ErrorBarsRenderAndBarLengthMatters) {
  Panel p;
  p.x = Axis{"condition", AxisScale::linear, std::nullopt, std::nullopt, false, {"wide-control", "wide-distractor"}};
  p.y = Axis{"proportion correct", AxisScale::linear, 0.0, 1.0, false};
  p.error_bars.push_back(ErrorBarSeries{{0, 1}, {0.8, 0.6}, {0.05, 0.1}, Rgb{0.1, 0.6, 0.1}, true, 3.5, 5.0, "mean ± SEM"});
  p.notes.push_back(TextNote{1, 0.9, "p = 0.03"});
  const std::string a = render_figure(one_panel(p), PlotFormat::png);
  EXPECT_GT(count_colour(a, {0.1, 0.6, 0.1}, 10), 30u);
  p.notes[0].dy_px = -12;  // the note moves up
  EXPECT_NE(render_figure(one_panel(p), PlotFormat::png), a);
  p.notes[0].dy_px = 0;
  EXPECT_EQ(render_figure(one_panel(p), PlotFormat::png), a);
  p.error_bars[0].error = {0.05, 0.2};
  EXPECT_NE(render_figure(one_panel(p), PlotFormat::png), a);
  EXPECT_FALSE(render_figure(one_panel(p), PlotFormat::svg).empty());
}

TEST(PlotStat, HeatmapColoursCellsByValueAndDrawsTheColourBar) {
  Panel p;
  p.title = "Similarity";
  p.x.label = "rendering";
  p.y.label = "reference";
  p.heatmap =
      HeatmapSeries{3, 3, {1, 2, 3, 4, 5, 6, 7, 8, 9}, {"r1", "r2", "r3"}, {"c1", "c2", "c3"}, 1.0, 9.0, 1, "mean rating"};
  const std::string png = render_figure(one_panel(p), PlotFormat::png);
  // The cell holding the maximum is the darkest class; the bar has it too.
  EXPECT_GT(count_colour(png, blues_darkest, 4), 1000u);
  EXPECT_GT(count_colour(png, blues_lightest, 2), 1000u);
  EXPECT_FALSE(render_figure(one_panel(p), PlotFormat::svg).empty());
  // Blank (NaN) cells and unlabelled matrices render too.
  p.heatmap = HeatmapSeries{2, 2, {1, std::nan(""), 3, 4}, {}, {}, std::nullopt, std::nullopt, -1, {}};
  EXPECT_FALSE(render_figure(one_panel(p), PlotFormat::png).empty());
}

TEST(PlotStat, DashedLineDiffersFromSolidAndSavesAtomically) {
  test_support::TempDir dir("texel-plot-stat");
  Panel p;
  p.x.label = "reference pitch (dB)";
  p.y.label = "matched pitch (dB)";
  p.lines.push_back(LineSeries{{-20, 20}, {-20, 20}, Rgb{0.4, 0.4, 0.4}, 1.0, "identity"});
  p.stems.push_back(StemSeries{{-10, 0, 10}, {-8, 1, 12}, std::nullopt, 0.0, false, 4.0, "matches"});
  const std::string solid = render_figure(one_panel(p), PlotFormat::png);
  p.lines[0].dashed = true;
  EXPECT_NE(render_figure(one_panel(p), PlotFormat::png), solid);
  save_figure(one_panel(p), dir.at("scatter.png"));
  EXPECT_EQ(read_file(dir.at("scatter.png")).substr(0, 4), std::string("\x89PNG", 4));
  EXPECT_EQ(dir.listing().size(), 1u);
}

TEST(PlotStat, MalformedSeriesThrowInvalidArgument) {
  const auto bad = [](Panel p) { EXPECT_THROW(render_figure(one_panel(std::move(p)), PlotFormat::png), InvalidArgument); };
  {
    Panel p = box_panel();
    p.boxes[0].positions = {0.0};  // two groups
    bad(p);
  }
  {
    Panel p = box_panel();
    p.boxes[0].box_width = 0;
    bad(p);
  }
  {
    Panel p;
    p.error_bars.push_back(ErrorBarSeries{{0, 1}, {1, 2}, {0.1}, std::nullopt, false, 3.5, 5.0, {}});
    bad(p);
  }
  {
    Panel p;
    p.error_bars.push_back(ErrorBarSeries{{0}, {1}, {-0.1}, std::nullopt, false, 3.5, 5.0, {}});
    bad(p);
  }
  {
    Panel p;
    p.error_bars.push_back(ErrorBarSeries{{0}, {1}, {0.1}, std::nullopt, false, 3.5, 99.0, {}});
    bad(p);
  }
  {
    Panel p;
    p.heatmap = HeatmapSeries{2, 2, {1, 2, 3}, {}, {}, std::nullopt, std::nullopt, 1, {}};
    bad(p);
  }
  {
    Panel p;
    p.heatmap = HeatmapSeries{2, 2, {1, 2, 3, 4}, {"only one"}, {}, std::nullopt, std::nullopt, 1, {}};
    bad(p);
  }
  {
    Panel p;
    p.heatmap = HeatmapSeries{2, 2, {1, 2, 3, 4}, {}, {}, 5.0, 1.0, 1, {}};
    bad(p);
  }
  {
    Panel p;
    p.heatmap = HeatmapSeries{1, 1, {1}, {}, {}, std::nullopt, std::nullopt, 9, {}};
    bad(p);
  }
  {
    Panel p;
    p.x = Axis{"f", AxisScale::log10, std::nullopt, std::nullopt, false, {"a", "b"}};
    bad(p);
  }
}
