// One serialiser per result type: the same session's JSON from the CLI
// (`texel experiment list --json`), from a studio reply (experiment.list
// through texel::studio::Service) and from the library's to_json() is the
// same document (tests/python/test_store.py checks Python's).
#include <gtest/gtest.h>

#include <chrono>

#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/service_client.hpp"
#include "../support/temp_dir.hpp"
#include "texel/experiment/store.hpp"
#include "texel/io.hpp"
#include "texel/studio/service.hpp"

namespace ex = texel::experiment;
using json = nlohmann::json;

namespace {

TEST(ResultJson, SessionIsTheSameFromCliStudioAndLibrary) {
  texel::test_support::TempDir dir("result-json");
  const std::string protocol = dir.at("p.json");
  texel::write_file_atomic(protocol, R"({"format": "texel-protocol", "version": 1, "name": "json-views", "study": "texel-length",
    "blocks": [{"name": "practice", "task": "oddity", "practice": true, "trials": 3, "variable": "texel_length_mm",
                "value": 20, "texture": {"kind": "texel", "central_pitch_db": 6, "irregularity_db": 0, "texel_length_mm": 20}}]})");
  const std::string db = dir.at("s.db");
  const auto ran = texel::test_support::run_cli(
      TEXEL_CLI, "experiment run " + protocol + " --participant P01 --db " + db + " --simulate default --quiet");
  ASSERT_EQ(ran.status, 0) << ran.out;
  const auto listed = texel::test_support::run_cli(TEXEL_CLI, "experiment list --db " + db + " --json", false);
  ASSERT_EQ(listed.status, 0) << listed.out;
  const json cli = json::parse(listed.out).at(0);
  EXPECT_EQ(cli["trials_done"], 3);
  EXPECT_EQ(cli["status"], "finished");

  const json library = json::parse(ex::to_json(ex::Store::open(db, ex::StoreMode::read_only).session(cli["id"])));
  EXPECT_EQ(library, cli);

  texel::studio::ServiceOptions o;
  o.db_path = db;
  texel::studio::Service service(o);
  const json reply = texel::test_support::Client(service).ask({{"type", "experiment.list"}}, std::chrono::seconds(60));
  ASSERT_EQ(reply["type"], "experiment.list") << reply.dump();
  ASSERT_EQ(reply["sessions"].size(), 1u);
  EXPECT_EQ(reply["sessions"][0], cli);

  // status --json embeds the same view of each session.
  const auto status = texel::test_support::run_cli(TEXEL_CLI, "experiment status --db " + db + " --json", false);
  json s = json::parse(status.out)["sessions"].at(0);
  s.erase("blocks");
  EXPECT_EQ(s, cli);
}

}  // namespace
