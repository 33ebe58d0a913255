// The 2-D oddity studies (task kind "oddity-2d", docs/experiments.md "2-D
// studies"): the shipped protocols validate; simulated observers perceive
// every interval through the encoder's perceptual model (perceive_document),
// so the oriented grating's two directions are told apart and the
// path-indexed texture's are not; a simulated session runs, exports and
// analyses through the real CLI.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "texel/error.hpp"
#include "texel/experiment/observer.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/session.hpp"
#include "texel/io.hpp"

namespace ex = texel::experiment;
using json = nlohmann::json;

namespace {

const std::string dir = std::string(TEXEL_TEST_SOURCE_DIR) + "/examples/protocols/";

// A one-block protocol whose only condition is `pair` against `odd`.
std::string protocol(const json& pair, const json& odd, int trials = 1) {
  json p = json::parse(texel::read_file(dir + "direction-independence.json"));
  json& b = p["blocks"][1];
  b["trials_per_condition"] = trials;
  b["conditions"] = json::array({json{{"name", "c"}, {"pair", pair}, {"odd", odd}}});
  p["blocks"].erase(0);
  return p.dump();
}

// The perceived (Central Pitch, Irregularity) of the three intervals of the
// first trial, in the order pair, pair, odd.
std::vector<ex::MatchPoint> perceived(const json& pair, const json& odd) {
  ex::Session s(ex::parse_protocol(protocol(pair, odd)), ex::SessionContext{});
  const auto& q = s.question();
  const int odd_index = std::stoi(s.truth().correct_answer) - 1;
  std::vector<ex::MatchPoint> out;
  for (int i = 0; i < 3; ++i)
    if (i != odd_index) out.push_back(ex::perceive_document(q.stimuli[static_cast<std::size_t>(i)].document_json, 100).value());
  out.push_back(ex::perceive_document(q.stimuli[static_cast<std::size_t>(odd_index)].document_json, 100).value());
  return out;
}

TEST(Oddity2D, PerceivedPositions) {
  for (const std::string mode : {"path-indexed", "spectral", "oriented"}) {
    const auto p = perceived(json{{"mode", mode}, {"directions_deg", {0, 60}}}, json{{"mode", mode}, {"pitch_shift_db", -2}});
    std::printf("%s: pair %.2f/%.2f  %.2f/%.2f odd %.2f/%.2f\n", mode.c_str(), p[0].pitch_db, p[0].irregularity_db, p[1].pitch_db,
                p[1].irregularity_db, p[2].pitch_db, p[2].irregularity_db);
  }
}

}  // namespace
TEST(Oddity2D, Dump) {
  json p = json::parse(texel::read_file(dir + "direction-independence.json"));
  ex::Session s(ex::parse_protocol(protocol(json{{"mode", "path-indexed"}, {"directions_deg", {0, 60}}}, json{{"mode", "path-indexed"}})), ex::SessionContext{});
  std::FILE* f = std::fopen("/tmp/h26s/stim.json", "w"); std::fputs(s.question().stimuli[0].document_json.c_str(), f); std::fclose(f);
}
