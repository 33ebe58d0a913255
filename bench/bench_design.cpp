// texel_bench_design: the studio designer's latency on the tpad (19,200
// samples), the timings that used to sit inside the unit tests
// DesignView.TpadLatency and Service.DesignRepliesWithTheLibrarysNumbers
// (performance belongs here, not in timed tests):
//   render      prepare_surface + render of the same document: the baseline
//   design_view the designer's numbers (map, histogram, spectrum, bitstream)
//   round trip  a `design` message through the Service (parse, design_view,
//               serialise the reply) as the server drives it, reply parsed
// Median and 95th percentile over N runs each (default 40; run i renders
// seed i + 1 in each measure), and the ratios to the baseline of the same
// run, so the figures compare across machines.
//
//   texel_bench_design [runs] [--json out.json]
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "texel/document.hpp"
#include "texel/studio/design.hpp"
#include "texel/studio/service.hpp"
#include "texel/surface.hpp"

namespace {

using json = nlohmann::json;
using clock_type = std::chrono::steady_clock;

struct Stats {
  double median_ms = 0.0;
  double p95_ms = 0.0;
};

Stats time_runs(int runs, const std::function<void(int)>& body) {
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(runs));
  for (int i = 0; i < runs; ++i) {
    const auto t0 = clock_type::now();
    body(i);
    ms.push_back(std::chrono::duration<double, std::milli>(clock_type::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms[std::min(ms.size() - 1, ms.size() * 95 / 100)]};
}

json tpad_document(double pitch_db, int seed) {
  return json{
      {"format", "texel-document"},
      {"version", 1},
      {"device", "tpad"},
      {"texture",
       {{"kind", "texel"}, {"central_pitch_db", pitch_db}, {"irregularity_db", -5}, {"texel_length_mm", 0.25}, {"seed", seed}}}};
}

// One client of the Service: the reply to each message, waited for.
struct Client {
  std::mutex m;
  std::condition_variable cv;
  std::vector<json> replies;
};

}  // namespace

int run(int argc, char** argv) {
  int runs = 40;
  std::string json_out;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--json" && i + 1 < argc)
      json_out = argv[++i];
    else
      runs = std::max(3, std::atoi(argv[i]));
  }
  // Run i uses seed i + 1 in every measure, so no cache of a prepared texture
  // or a view serves a run from the one before.
  std::vector<texel::Document> docs;
  docs.reserve(static_cast<std::size_t>(runs));
  for (int i = 0; i < runs; ++i) docs.push_back(texel::parse_document(tpad_document(10.0, i + 1).dump()));
  double keep = 0.0;  // keeps the results alive

  const Stats render = time_runs(runs, [&](int i) {
    const std::vector<double> map = texel::prepare_surface(docs[static_cast<std::size_t>(i)]).render();
    keep += map[map.size() / 2];
  });
  const Stats design = time_runs(runs, [&](int i) {
    const texel::studio::DesignView v = texel::studio::design_view(docs[static_cast<std::size_t>(i)]);
    keep += static_cast<double>(v.encoded.size());
  });

  const std::filesystem::path db = std::filesystem::temp_directory_path() /
                                   ("texel-bench-design-" + std::to_string(clock_type::now().time_since_epoch().count()) + ".db");
  std::size_t reply_bytes = 0;
  Stats round_trip;
  {
    texel::studio::ServiceOptions o;
    o.db_path = db.string();
    texel::studio::Service service(o);
    Client c;
    const std::uint64_t id = service.connect([&c](const std::string& text) {
      json j = json::parse(text);
      std::lock_guard lock(c.m);
      c.replies.push_back(std::move(j));
      c.cv.notify_all();
    });
    round_trip = time_runs(runs, [&](int i) {
      const json msg{{"type", "design"}, {"id", i}, {"document", tpad_document(10.0, i + 1)}};
      service.handle(id, msg.dump());
      std::unique_lock lock(c.m);
      c.cv.wait(lock, [&] { return !c.replies.empty(); });
      const json r = std::move(c.replies.back());
      c.replies.clear();
      if (r.value("type", "") != "design") {
        std::fprintf(stderr, "texel_bench_design: the service answered %s\n", r.dump().c_str());
        std::exit(1);
      }
      reply_bytes = r.dump().size();
    });
    service.disconnect(id);
  }
  std::error_code ec;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) std::filesystem::remove(db.string() + suffix, ec);

  std::printf("tpad (19,200 samples), %d runs each      median ms   p95 ms   median / render\n", runs);
  std::printf("render (prepare + render, baseline)      %9.2f %8.2f   %6.2f\n", render.median_ms, render.p95_ms, 1.0);
  std::printf("design_view                              %9.2f %8.2f   %6.2f\n", design.median_ms, design.p95_ms,
              design.median_ms / render.median_ms);
  std::printf("design message round trip (%zu B reply) %9.2f %8.2f   %6.2f\n", reply_bytes, round_trip.median_ms,
              round_trip.p95_ms, round_trip.median_ms / render.median_ms);
  if (!json_out.empty()) {
    const json out{
        {"runs", runs},
        {"render", {{"median_ms", render.median_ms}, {"p95_ms", render.p95_ms}}},
        {"design_view", {{"median_ms", design.median_ms}, {"p95_ms", design.p95_ms}}},
        {"round_trip", {{"median_ms", round_trip.median_ms}, {"p95_ms", round_trip.p95_ms}, {"reply_bytes", reply_bytes}}}};
    std::ofstream(json_out) << out.dump(2) << "\n";
  }
  return keep == -1.0 ? 1 : 0;
}

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "texel_bench_design: %s\n", e.what());
    return 1;
  }
}
