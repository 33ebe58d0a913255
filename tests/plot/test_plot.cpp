// Plot output: file formats and their headers, atomic writes and the errors
// a user can cause, tick placement, histogram binning, and the per-column
// decimation of long series against the undecimated drawing.
#include <gtest/gtest.h>

#include <cairo.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <unistd.h>

#include "../support/temp_dir.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/plot.hpp"

namespace fs = std::filesystem;
using namespace texel;

namespace {

/// The shared per-test directory (tests/support/temp_dir.hpp), with this file's names.
struct TempDir : texel::test_support::TempDir {
  TempDir() : texel::test_support::TempDir("texel-plot") {}
  [[nodiscard]] std::string file(const std::string& name) const { return at(name); }
  [[nodiscard]] std::size_t entries() const { return listing().size(); }
};

std::uint32_t be32(const std::string& b, std::size_t at) {
  return (static_cast<std::uint32_t>(static_cast<unsigned char>(b[at])) << 24) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 1])) << 16) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 2])) << 8) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 3]));
}

const std::string png_signature("\x89PNG\r\n\x1a\n", 8);

/// Width and height from a PNG's IHDR chunk (which must come first).
std::pair<std::uint32_t, std::uint32_t> png_size(const std::string& bytes) {
  EXPECT_GE(bytes.size(), 33u);
  EXPECT_EQ(bytes.substr(0, 8), png_signature);
  EXPECT_EQ(bytes.substr(12, 4), "IHDR");
  return {be32(bytes, 16), be32(bytes, 20)};
}

Figure sine_figure(std::size_t n = 2000) {
  Figure fig;
  fig.width_px = 640;
  fig.height_px = 480;
  fig.title = "test";
  Panel p;
  p.title = "sine";
  p.x.label = "position (mm)";
  p.y.label = "amplitude";
  LineSeries s;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = 10.0 * static_cast<double>(i) / static_cast<double>(n);
    s.x.push_back(x);
    s.y.push_back(0.5 + 0.5 * std::sin(2 * std::numbers::pi * x));
  }
  s.label = "a";
  p.lines.push_back(s);
  s.label = "b";
  for (auto& y : s.y) y = 1 - y;
  p.lines.push_back(s);
  fig.panels.push_back(p);
  return fig;
}

MapPlot sample_map() {
  MapPlot m;
  m.title = "sample";
  for (int i = 0; i < 4000; ++i) {
    const double x = 0.01 * i;
    m.positions_mm.push_back(x);
    m.amplitudes.push_back(0.5 + 0.5 * std::sin(2 * std::numbers::pi * 3 * x));
  }
  for (int i = 0; i < 160; ++i) m.frequencies_cpm.push_back(std::exp(std::log(3.0) + 0.4 * std::sin(i * 1.7)));
  m.central_pitch = CyclesPerMm(3.0);
  return m;
}

std::vector<double> major_values(const std::vector<Tick>& ticks) {
  std::vector<double> out;
  for (const auto& t : ticks)
    if (t.major) out.push_back(t.value);
  return out;
}

cairo_status_t read_from_string(void* closure, unsigned char* data, unsigned int length) {
  auto* src = static_cast<std::pair<const std::string*, std::size_t>*>(closure);
  if (src->second + length > src->first->size()) return CAIRO_STATUS_READ_ERROR;
  std::copy_n(src->first->data() + src->second, length, data);
  src->second += length;
  return CAIRO_STATUS_SUCCESS;
}

/// Decoded 0xXXRRGGBB pixels of a PNG.
std::vector<std::uint32_t> png_pixels(const std::string& bytes, int& w, int& h) {
  std::pair<const std::string*, std::size_t> src{&bytes, 0};
  cairo_surface_t* s = cairo_image_surface_create_from_png_stream(read_from_string, &src);
  EXPECT_EQ(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
  cairo_surface_flush(s);
  w = cairo_image_surface_get_width(s);
  h = cairo_image_surface_get_height(s);
  const int stride = cairo_image_surface_get_stride(s);
  const unsigned char* data = cairo_image_surface_get_data(s);
  std::vector<std::uint32_t> px;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) px.push_back(reinterpret_cast<const std::uint32_t*>(data + y * stride)[x] & 0xFFFFFFu);
  cairo_surface_destroy(s);
  return px;
}

}  // namespace

// ------------------------------------------------------------------ formats

TEST(Plot, PngHasSignatureAndRequestedSize) {
  Figure fig = sine_figure();
  fig.width_px = 733;
  fig.height_px = 411;
  const auto [w, h] = png_size(render_figure(fig, PlotFormat::png));
  EXPECT_EQ(w, 733u);
  EXPECT_EQ(h, 411u);
}

TEST(Plot, SavedPngIsTheRenderedBytes) {
  TempDir dir;
  const Figure fig = sine_figure();
  save_figure(fig, dir.file("a.png"));
  const std::string bytes = read_file(dir.file("a.png"));
  EXPECT_EQ(bytes.substr(0, 8), png_signature);
  EXPECT_EQ(png_size(bytes), (std::pair<std::uint32_t, std::uint32_t>{640, 480}));
  EXPECT_EQ(dir.entries(), 1u) << "no temporary left beside the output";
}

TEST(Plot, SvgIsXmlText) {
  TempDir dir;
  save_figure(sine_figure(), dir.file("a.svg"));
  const std::string text = read_file(dir.file("a.svg"));
  ASSERT_FALSE(text.empty());
  EXPECT_TRUE(text.starts_with("<?xml") || text.starts_with("<svg")) << text.substr(0, 40);
  EXPECT_NE(text.find("<svg"), std::string::npos);
  EXPECT_NE(text.find("</svg>"), std::string::npos);
  EXPECT_NE(text.find("width=\"640"), std::string::npos);
  EXPECT_EQ(text.find('\0'), std::string::npos);
}

TEST(Plot, ExtensionIsCaseInsensitive) {
  TempDir dir;
  save_figure(sine_figure(), dir.file("UPPER.PNG"));
  EXPECT_EQ(read_file(dir.file("UPPER.PNG")).substr(0, 8), png_signature);
  save_figure(sine_figure(), dir.file("Mixed.Svg"));
  EXPECT_NE(read_file(dir.file("Mixed.Svg")).find("<svg"), std::string::npos);
  EXPECT_EQ(plot_format_for_path("x/y.Png"), PlotFormat::png);
}

// ------------------------------------------------------------------- errors

TEST(Plot, UnknownExtensionThrowsInvalidArgumentNamingIt) {
  TempDir dir;
  try {
    save_figure(sine_figure(), dir.file("plot.jpg"));
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(".jpg"), std::string::npos) << msg;
    EXPECT_NE(msg.find(".png"), std::string::npos) << msg;
    EXPECT_NE(msg.find(".svg"), std::string::npos) << msg;
  }
  EXPECT_THROW(save_figure(sine_figure(), dir.file("noextension")), InvalidArgument);
  EXPECT_THROW(plot_map(sample_map(), dir.file("map.pdf")), InvalidArgument);
  EXPECT_EQ(dir.entries(), 0u);
}

TEST(Plot, UnwritableDirectoryThrowsIoErrorAndLeavesNothing) {
  TempDir dir;
  const std::string missing = dir.file("no-such-dir/plot.png");
  EXPECT_THROW(save_figure(sine_figure(), missing), IoError);
  EXPECT_FALSE(fs::exists(missing));
  // A regular file where the directory should be (fails even for root, unlike chmod).
  write_file_atomic(dir.file("file"), "x");
  EXPECT_THROW(save_figure(sine_figure(), dir.file("file/plot.svg")), IoError);
  EXPECT_THROW(plot_map(sample_map(), dir.file("file/map.png")), IoError);
  EXPECT_EQ(dir.entries(), 1u) << "only the file the test made";
}

TEST(Plot, BadFiguresThrowInvalidArgument) {
  Figure fig = sine_figure();
  fig.width_px = 10;
  EXPECT_THROW(render_figure(fig, PlotFormat::png), InvalidArgument);
  fig = sine_figure();
  fig.panels[0].lines[0].y.pop_back();
  EXPECT_THROW(render_figure(fig, PlotFormat::png), InvalidArgument);
  fig = sine_figure();
  fig.panels[0].x.scale = AxisScale::log10;
  fig.panels[0].x.min = 0.0;
  EXPECT_THROW(render_figure(fig, PlotFormat::svg), InvalidArgument);
  fig = sine_figure();
  fig.panels[0].y.min = 2.0;
  fig.panels[0].y.max = 1.0;
  EXPECT_THROW(render_figure(fig, PlotFormat::png), InvalidArgument);
  fig = sine_figure();
  fig.panels[0].histograms.push_back(Histogram{{0, 1, 2}, {1}, std::nullopt, {}});
  EXPECT_THROW(render_figure(fig, PlotFormat::png), InvalidArgument);
  fig = sine_figure();
  fig.columns = 0;
  EXPECT_THROW(render_figure(fig, PlotFormat::png), InvalidArgument);
  MapPlot m = sample_map();
  m.amplitudes.pop_back();
  EXPECT_THROW(map_figure(m), InvalidArgument);
  EXPECT_THROW(map_figure(MapPlot{}), InvalidArgument);
}

// --------------------------------------------------------------- rendering

TEST(Plot, EveryElementKindRenders) {
  Figure fig;
  fig.columns = 2;
  Panel a;
  a.x = Axis{"f (cpm)", AxisScale::log10, std::nullopt, std::nullopt, true};
  a.lines.push_back(LineSeries{{0.1, 1, 10, 100}, {1, 3, 2, 0}, std::nullopt, 1.25, "spectrum"});
  a.stems.push_back(StemSeries{{1, 10}, {3, 2}, std::nullopt, 0.0, true, 3.0, "peaks"});
  a.markers.push_back({5.0, "marker", {0.5, 0, 0}, true});
  a.markers.push_back({-5.0, "not drawn on a log axis", {0.5, 0, 0}, true});
  Panel b;
  b.y.scale = AxisScale::log10;
  b.histograms.push_back(make_histogram(std::vector<double>{1, 2, 2, 3, 3, 3}, 3));
  b.lines.push_back(LineSeries{{0, 1, 2}, {std::nan(""), 0.0, -1.0}, std::nullopt, 1.0, {}});  // nothing drawable on log y
  Panel empty;
  fig.panels = {a, b, empty};
  for (const auto format : {PlotFormat::png, PlotFormat::svg}) EXPECT_FALSE(render_figure(fig, format).empty());
  Figure blank;
  EXPECT_EQ(png_size(render_figure(blank, PlotFormat::png)).first, 1000u);
}

TEST(Plot, MillionPointSeriesRenders) {
  Figure fig;
  Panel p;
  LineSeries s;
  const std::size_t n = 1'000'000;
  s.x.resize(n);
  s.y.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    s.x[i] = 1e-4 * static_cast<double>(i);
    s.y[i] = std::sin(0.01 * static_cast<double>(i)) + 0.2 * std::sin(0.37 * static_cast<double>(i));
  }
  p.lines.push_back(std::move(s));
  fig.panels.push_back(std::move(p));
  // Decimation keeps this to a few thousand vertices; no timing assertion
  // (benchmarks are separate targets), but an undecimated path would take seconds.
  const auto [w, h] = png_size(render_figure(fig, PlotFormat::png));
  EXPECT_EQ(w, 1000u);
  EXPECT_EQ(h, 700u);
  EXPECT_FALSE(render_figure(fig, PlotFormat::svg).empty());
}

TEST(Plot, DecimatedLineMatchesUndecimatedDrawing) {
  // The slow, obviously correct reference: the same points drawn one by one.
  // An unsorted series is never decimated, so a leading point with a NaN y
  // (which draws nothing) turns the fast path off.
  const std::size_t n = 200'000;
  LineSeries fast;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i) / static_cast<double>(n);
    fast.x.push_back(x);
    fast.y.push_back(std::sin(2 * std::numbers::pi * 40 * x) * std::exp(-2 * x) + 0.3 * std::sin(2 * std::numbers::pi * 900 * x));
  }
  fast.colour = Rgb{0, 0, 0};
  LineSeries slow = fast;
  slow.x.insert(slow.x.begin(), 0.5);
  slow.y.insert(slow.y.begin(), std::nan(""));
  const auto draw = [](const LineSeries& s) {
    Figure fig;
    fig.width_px = 500;
    fig.height_px = 300;
    Panel p;
    p.x.min = 0.0;
    p.x.max = 1.0;
    p.y.min = -1.5;
    p.y.max = 1.5;
    p.lines.push_back(s);
    fig.panels.push_back(p);
    return render_figure(fig, PlotFormat::png);
  };
  int w = 0, h = 0;
  const auto a = png_pixels(draw(fast), w, h);
  const auto b = png_pixels(draw(slow), w, h);
  ASSERT_EQ(a.size(), b.size());
  std::size_t differ = 0, inked = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto grey = [](std::uint32_t p) { return static_cast<int>(p & 0xFF); };
    if (std::abs(grey(a[i]) - grey(b[i])) > 96) ++differ;
    if (grey(b[i]) < 128) ++inked;
  }
  // Antialiasing at column joins differs slightly; the picture must not.
  EXPECT_GT(inked, 1000u);
  EXPECT_LT(static_cast<double>(differ), 0.005 * static_cast<double>(inked))
      << differ << " of " << inked << " inked pixels differ";
}

// -------------------------------------------------------------------- ticks

TEST(PlotTicks, LogAxisFromTenthToHundredCpmIsDecades) {
  const auto ticks = axis_ticks(0.1, 100.0, AxisScale::log10, true);
  const auto majors = major_values(ticks);
  ASSERT_EQ(majors.size(), 4u);
  const double expected[] = {0.1, 1, 10, 100};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(majors[i], expected[i], expected[i] * 1e-12);
  std::vector<std::string> labels, secondary;
  for (const auto& t : ticks)
    if (t.major) labels.push_back(t.label), secondary.push_back(t.secondary);
  EXPECT_EQ(labels, (std::vector<std::string>{"0.1", "1", "10", "100"}));
  EXPECT_EQ(secondary, (std::vector<std::string>{"(\u221210 dB)", "(0 dB)", "(10 dB)", "(20 dB)"}));
  // Minor ticks at 2 … 9 of each decade, unlabelled.
  std::size_t minors = 0;
  for (const auto& t : ticks)
    if (!t.major) {
      ++minors;
      EXPECT_TRUE(t.label.empty());
    }
  EXPECT_EQ(minors, 3u * 8u);
}

TEST(PlotTicks, ManyDecadesAreThinned) {
  const auto majors = major_values(axis_ticks(1e-6, 1e6, AxisScale::log10, false, 6));
  ASSERT_GE(majors.size(), 3u);
  EXPECT_LE(majors.size(), 7u);
  for (const double v : majors) EXPECT_NEAR(std::log10(v), std::round(std::log10(v)), 1e-9);
}

TEST(PlotTicks, NarrowLogRangeStillHasTicks) {
  const auto majors = major_values(axis_ticks(2.5, 4.0, AxisScale::log10));
  EXPECT_GE(majors.size(), 2u);
  for (const double v : majors) {
    EXPECT_GE(v, 2.5);
    EXPECT_LE(v, 4.0);
  }
}

TEST(PlotTicks, LinearTicksAreOneTwoFiveSteps) {
  const auto ticks = axis_ticks(0.0, 1.0, AxisScale::linear, false, 5);
  std::vector<std::string> labels;
  for (const auto& t : ticks) labels.push_back(t.label);
  EXPECT_EQ(labels, (std::vector<std::string>{"0.0", "0.2", "0.4", "0.6", "0.8", "1.0"}));
  const auto tenths = axis_ticks(0.0, 1.0, AxisScale::linear, false, 10);
  EXPECT_EQ(tenths[3].label, "0.3");  // k·step, never 0.30000000000000004
  const auto big = major_values(axis_ticks(-37.0, 512.0, AxisScale::linear, false, 6));
  ASSERT_GE(big.size(), 2u);
  const double step = big[1] - big[0];
  EXPECT_DOUBLE_EQ(step, 100.0);
  EXPECT_EQ(axis_ticks(-2.0, 2.0, AxisScale::linear, false, 4).front().label, "\u22122");
}

TEST(PlotTicks, BadRangesThrow) {
  EXPECT_THROW(axis_ticks(1.0, 1.0, AxisScale::linear), InvalidArgument);
  EXPECT_THROW(axis_ticks(0.0, 10.0, AxisScale::log10), InvalidArgument);
  EXPECT_THROW(axis_ticks(0.0, std::nan(""), AxisScale::linear), InvalidArgument);
}

// --------------------------------------------------------------- histogram

TEST(PlotHistogram, CountsEveryUsableValueOnce) {
  std::vector<double> v;
  for (int i = 0; i < 1000; ++i) v.push_back(std::pow(10.0, -1.0 + 3.0 * i / 999.0));
  v.push_back(-1.0);          // not on a log axis
  v.push_back(std::nan(""));  // never
  const Histogram h = make_histogram(v, 30, AxisScale::log10);
  ASSERT_EQ(h.counts.size(), 30u);
  ASSERT_EQ(h.edges.size(), 31u);
  double total = 0;
  for (const double c : h.counts) total += c;
  EXPECT_EQ(total, 1000.0);
  EXPECT_NEAR(h.edges.front(), 0.1, 1e-12);
  EXPECT_NEAR(h.edges.back(), 100.0, 1e-9);
  // Equal width in log: constant ratio between edges.
  EXPECT_NEAR(h.edges[1] / h.edges[0], h.edges[30] / h.edges[29], 1e-9);
  EXPECT_TRUE(make_histogram(std::vector<double>{}, 0).counts.empty());
  const Histogram one = make_histogram(std::vector<double>{2.0, 2.0}, 0, AxisScale::log10);
  ASSERT_FALSE(one.edges.empty());
  EXPECT_LT(one.edges.front(), 2.0);
  EXPECT_GT(one.edges.back(), 2.0);
}

// ----------------------------------------------------------- texture plots

TEST(PlotMap, FigureHasMapExcerptAndHistogram) {
  const Figure fig = map_figure(sample_map());
  ASSERT_EQ(fig.panels.size(), 3u);
  EXPECT_EQ(fig.panels[1].x.max.value() - fig.panels[1].x.min.value(), 6.0);
  EXPECT_EQ(fig.panels[2].x.scale, AxisScale::log10);
  EXPECT_TRUE(fig.panels[2].x.db_labels);
  MapPlot no_extras = sample_map();
  no_extras.frequencies_cpm.clear();
  no_extras.excerpt = Millimetres(0.0);
  EXPECT_EQ(map_figure(no_extras).panels.size(), 1u);
}

TEST(PlotMap, WritesPngAndSvg) {
  TempDir dir;
  plot_map(sample_map(), dir.file("map.png"));
  plot_map(sample_map(), dir.file("map.svg"));
  const auto [w, h] = png_size(read_file(dir.file("map.png")));
  EXPECT_EQ(w, 1000u);
  EXPECT_GT(h, 600u);
  EXPECT_NE(read_file(dir.file("map.svg")).find("</svg>"), std::string::npos);
  EXPECT_EQ(dir.entries(), 2u);
}

TEST(PlotMap, GridIsColumnsTimesCells) {
  TempDir dir;
  std::vector<MapPlot> maps(5, sample_map());
  plot_map_grid(maps, dir.file("atlas.png"), 3, "atlas");
  const auto [w, h] = png_size(read_file(dir.file("atlas.png")));
  EXPECT_EQ(w, 3u * 440u);
  EXPECT_GT(h, 2u * 380u);  // two rows plus the title band
  EXPECT_LT(h, 2u * 380u + 100u);
  EXPECT_THROW(plot_map_grid(maps, dir.file("atlas.png"), 0), InvalidArgument);
  EXPECT_THROW(plot_map_grid(std::span<const MapPlot>{}, dir.file("empty.png")), InvalidArgument);
}
