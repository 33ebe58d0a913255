// texel_bench_presenter_2d: where a 2-D study's wait before a trial goes
// (docs/experiments.md "The 2-D display presenter"). For a protocol of
// oddity-2d blocks it runs one session's trials and times, per trial, the
// engine preparing the question (its scans) and, per surface the display
// would play, the steps of rendering its map: parsing and preparing the
// version-4 document (prepare_surface2d), rendering the friction bitmap
// (render_raster, and the former row-at-a-time rendering it replaced, which
// must give the same floats) and making the player's map (PlayerMap2D).
// The engine's questions run first, so the surfaces they prepared are
// shared (prepared_surfaces.hpp) and "prepare_surface2d" here is the cost
// the presenter paid before it shared them. The sum is what the presenter
// renders over a session: its preload does it in the background.
//
//   texel_bench_presenter_2d PROTOCOL.json [--json PATH]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "texel/document.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/session.hpp"
#include "texel/io.hpp"
#include "texel/player2d.hpp"
#include "texel/surface2d.hpp"

namespace ex = texel::experiment;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: texel_bench_presenter_2d PROTOCOL.json [--json PATH]\n";
    return 2;
  }
  std::string json_path;
  for (int i = 2; i + 1 < argc; i += 2)
    if (std::string(argv[i]) == "--json") json_path = argv[i + 1];
  const std::string text = texel::read_file(argv[1]);
  nlohmann::json out;

  // The engine: each question as the session prepares it (the first in
  // the constructor, every next one in answer()).
  ex::SessionContext context;
  context.participant = "BENCH";
  auto t0 = Clock::now();
  ex::Session session(ex::parse_protocol(text), context);
  double engine_s = since(t0), engine_max_s = engine_s;
  std::vector<ex::Question> questions;
  std::vector<std::string> conditions;
  std::vector<double> engine_trial_s;
  engine_trial_s.push_back(engine_s);
  while (!session.finished()) {
    questions.push_back(session.question());
    conditions.push_back(session.truth().condition);
    ex::Response r;
    r.choice = "1";
    t0 = Clock::now();
    (void)session.answer(r);
    const double s = since(t0);
    if (!session.finished()) {
      engine_trial_s.push_back(s);
      engine_s += s;
      engine_max_s = std::max(engine_max_s, s);
    }
  }

  // The display's maps: each distinct surface once, step by step.
  std::set<std::string> seen;
  double row_by_row_s = 0, parse_s = 0, prepare_s = 0, raster_s = 0, map_s = 0, path_s = 0;
  int bitmaps = 0, paths = 0;
  std::map<std::string, double> first_wait;  // condition -> maps of its first trial
  for (std::size_t k = 0; k < questions.size(); ++k) {
    double wait = 0;
    for (const ex::SurfaceStimulus& s : questions[k].surfaces) {
      if (!seen.insert(s.document_json).second) continue;
      t0 = Clock::now();
      const texel::Document doc = texel::parse_document(s.document_json, "surface");
      double a = since(t0);
      parse_s += a;
      if (s.kind == ex::SurfaceStimulus::Kind::bitmap) {
        t0 = Clock::now();
        const texel::Surface2D surface = texel::prepare_surface2d(doc);
        const double b = since(t0);
        t0 = Clock::now();
        texel::Raster2D raster = texel::render_raster(surface);
        const double c = since(t0);
        // The former render_raster, a row at a time: its time, and the
        // same floats (the strips must not change a bit).
        t0 = Clock::now();
        std::vector<float> rows(raster.values.size());
        std::vector<double> row(static_cast<std::size_t>(surface.geometry().width));
        for (int j = 0; j < surface.geometry().height; ++j) {
          surface.render_rows(j, 1, row);
          std::transform(row.begin(), row.end(), rows.begin() + static_cast<std::ptrdiff_t>(j) * surface.geometry().width,
                         [](double v) { return static_cast<float>(v); });
        }
        row_by_row_s += since(t0);
        if (std::memcmp(rows.data(), raster.values.data(), rows.size() * sizeof(float)) != 0) {
          std::cerr << "render_raster differs from the row-by-row rendering\n";
          return 1;
        }
        t0 = Clock::now();
        auto m = texel::PlayerMap2D::bitmap(std::move(raster), doc.device.response);
        const double d = since(t0);
        prepare_s += b;
        raster_s += c;
        map_s += d;
        a += b + c + d;
        ++bitmaps;
      } else {
        const texel::BitmapGeometry& g = *doc.device.bitmap;
        t0 = Clock::now();
        auto m = texel::PlayerMap2D::path_indexed(
            doc.surface2d->regions[0].texel, texel::Sampling{doc.device.grid(), texel::CyclesPerMm(0.0)}, std::nullopt,
            texel::Extent2D{0.0, 0.0, g.width_mm().value(), g.height_mm().value()}, 10000.0, doc.device.response);
        const double b = since(t0);
        path_s += b;
        a += b;
        ++paths;
      }
      wait += a;
    }
    if (!first_wait.contains(conditions[k])) first_wait[conditions[k]] = wait + engine_trial_s[k];
  }

  std::printf("protocol %s: %zu trials, %d bitmap surfaces, %d path-indexed surfaces\n", argv[1], questions.size(), bitmaps,
              paths);
  std::printf("engine (questions, their scans): %.2f s in all, at most %.2f s for one trial\n", engine_s, engine_max_s);
  std::printf("bitmap maps: parse %.2f s, prepare_surface2d %.2f s, render_raster %.2f s, PlayerMap2D %.2f s (%.2f s each)\n",
              parse_s, prepare_s, raster_s, map_s, bitmaps ? (prepare_s + raster_s + map_s) / bitmaps : 0.0);
  std::printf("render_raster a row at a time (the former code): %.2f s, the same floats\n", row_by_row_s);
  std::printf("path-indexed maps: %.3f s in all\n", path_s);
  std::printf("first trial of each condition, engine + its new maps, without the presenter's preload:\n");
  for (const auto& [c, w] : first_wait) std::printf("  %-24s %.2f s\n", c.c_str(), w);

  out = {{"protocol", argv[1]},
         {"trials", questions.size()},
         {"engine_s", engine_s},
         {"engine_max_trial_s", engine_max_s},
         {"bitmaps", bitmaps},
         {"prepare_surface2d_s", prepare_s},
         {"render_raster_s", raster_s},
         {"render_rows_one_at_a_time_s", row_by_row_s},
         {"player_map_s", map_s},
         {"path_indexed_s", path_s},
         {"first_trial_wait_s", first_wait}};
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  return 0;
}
