// A task kind added the way docs/experiments.md "Adding a task kind" says —
// one type and one registration (press_side_task.cpp) — runs end to end:
// validated in a protocol, run by simulated participants and stored,
// exported as CSV, and run through the studio's experiment messages
// (texel::studio::Service); then through the real CLI, `texel_with_test_kind`
// (the shipped CLI's objects plus press_side_task.cpp): `experiment run
// --simulate`, `experiment export` and `experiment list`, while the shipped
// `texel` does not know the kind. The built-in kinds' declared export columns
// all exist.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "../support/cli_run.hpp"
#include "../support/expect.hpp"
#include "../support/service_client.hpp"
#include "../support/temp_dir.hpp"
#include "task.hpp"
#include "texel/error.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/runner.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/experiment/store.hpp"
#include "texel/io.hpp"
#include "texel/studio/service.hpp"

namespace ex = texel::experiment;
using json = nlohmann::json;
using namespace std::chrono_literals;

namespace {

// The test-only kind "press-side" (press_side_task.cpp, linked into this
// program) and its protocol.
const std::string protocol_path = std::string(TEXEL_TEST_SOURCE_DIR) + "/tests/experiment/data/press-side.json";
const std::string protocol_text = texel::read_file(protocol_path);

TEST(TaskKind, TestOnlyKindIsValidatedLikeABuiltInOne) {
  ASSERT_NE(ex::find_task_type("press-side"), nullptr);
  const auto names = ex::task_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "press-side"), names.end());
  const ex::Protocol p = ex::parse_protocol(protocol_text);
  EXPECT_EQ(p.planned_trials(), 7);
  auto message = [](const std::string& from, const std::string& to) {
    std::string text = protocol_text;
    text.replace(text.find(from), from.size(), to);
    return texel::test_support::message_of<texel::FormatError>([&] { (void)ex::parse_protocol(text); });
  };
  EXPECT_NE(message("\"presses\": 5", "\"presses\": 500").find("blocks[1].presses is 500"), std::string::npos);
  EXPECT_NE(message("\"presses\": 5", "\"presses\": 5, \"staircase\": {}")
                .find("blocks[1].staircase does not apply to task "
                      "'press-side'"),
            std::string::npos);
  EXPECT_NE(message("\"presses\": 5", "\"presses\": 5, \"pressess\": 1").find("unknown key 'pressess'"), std::string::npos);
  // A built-in kind refuses the new kind's key.
  EXPECT_NE(message("\"task\": \"press-side\", \"presses\": 5",
                    "\"task\": \"match\", \"references\": [\"bandpass-f1-z0.5\"], \"presses\": 5")
                .find("blocks[1].presses does not apply to task 'match'"),
            std::string::npos);
}

TEST(TaskKind, TestOnlyKindRunsSimulatedStoredAndExported) {
  texel::test_support::TempDir dir("task-kind");
  ex::Store store = ex::Store::open(dir.at("s.db"), ex::StoreMode::read_write);
  const ex::Protocol p = ex::parse_protocol(protocol_text);
  const auto ids = ex::simulate_cohort(store, p, {"P01", "P02"});
  ASSERT_EQ(ids.size(), 2u);
  const auto rows = store.rows();
  ASSERT_EQ(rows.size(), 14u);
  int correct = 0;
  for (const auto& r : rows) {
    EXPECT_EQ(r.task, "press-side");
    EXPECT_TRUE(r.response == "left" || r.response == "right");
    correct += r.correct == 1.0;
  }
  EXPECT_GT(correct, 7);
  EXPECT_EQ(store.session(ids[0]).status, "finished");
  // Export: the same rows through the CSV `texel experiment export` writes.
  const std::string csv = ex::trials_csv(rows);
  EXPECT_NE(csv.find(",press-side,"), std::string::npos);
  EXPECT_EQ(ex::trials_csv(ex::parse_trials_csv(csv, "export")), csv);
  // Resume is replay: a session rebuilt from the stored trials asks the same.
  ex::SessionContext c;
  c.participant = "P01";
  c.session_id = ids[0];
  c.seed = store.session(ids[0]).seed;
  ex::Session again(p, c);
  for (const auto& t : store.trials(ids[0])) again.replay(t);
  EXPECT_TRUE(again.finished());
}

TEST(TaskKind, TestOnlyKindRunsThroughTheStudio) {
  texel::test_support::TempDir dir("task-kind-studio");
  texel::studio::ServiceOptions o;
  o.db_path = dir.at("s.db");
  texel::studio::Service service(o);
  texel::test_support::Client client(service);
  auto ask = [&](json msg) { return client.ask(std::move(msg), 60s); };
  const json started = ask(
      {{"type", "experiment.start"}, {"protocol", json::parse(protocol_text)}, {"participant", "P01"}, {"simulate", "default"}});
  ASSERT_EQ(started["type"], "experiment.started") << started.dump();
  EXPECT_EQ(started["progress"]["planned"], 7);
  json q = ask({{"type", "experiment.current"}});
  int answered = 0;
  while (q["type"] == "experiment.question") {
    EXPECT_EQ(q["question"]["task"], "press-side");
    EXPECT_EQ(q["question"]["choices"], json({"left", "right"}));
    q = ask({{"type", "experiment.answer"}, {"trial", q["question"]["trial"]}, {"simulated", true}});
    ++answered;
  }
  EXPECT_EQ(q["type"], "experiment.finished") << q.dump();
  EXPECT_EQ(answered, 7);
  const json list = ask({{"type", "experiment.list"}});
  ASSERT_EQ(list["sessions"].size(), 1u);
  EXPECT_EQ(list["sessions"][0]["status"], "finished");
}

// The real CLI with the kind: a simulated run stores it, the export CSV has
// the kind's columns filled on every row, the session is listed finished.
TEST(TaskKind, TestOnlyKindRunsThroughTheCliBinary) {
  texel::test_support::TempDir dir("task-kind-cli");
  const std::string db = dir.at("s.db"), csv_path = dir.at("trials.csv");
  auto cli = [](const std::string& args) { return texel::test_support::run_cli(TEXEL_WITH_TEST_KIND, args); };
  for (const char* who : {"P01", "P02"}) {
    const auto run =
        cli("experiment run " + protocol_path + " --participant " + who + " --db " + db + " --simulate default --quiet");
    ASSERT_EQ(run.status, 0) << run.out;
  }
  const auto exported = cli("experiment export --db " + db + " -o " + csv_path);
  ASSERT_EQ(exported.status, 0) << exported.out;
  const std::string csv = texel::read_file(csv_path);
  const auto rows = ex::parse_trials_csv(csv, "export");
  ASSERT_EQ(rows.size(), 14u);
  // The CSV's header names every column the kind declares, and its rows fill them.
  const std::string header = csv.substr(0, csv.find('\n'));
  for (std::string_view c : ex::find_task_type("press-side")->columns())
    EXPECT_NE(("," + header + ",").find("," + std::string(c) + ","), std::string::npos) << c;
  int correct = 0;
  for (const auto& r : rows) {
    EXPECT_EQ(r.task, "press-side");
    EXPECT_TRUE(r.response == "left" || r.response == "right") << r.response;
    EXPECT_TRUE(r.correct_answer == "left" || r.correct_answer == "right") << r.correct_answer;
    correct += r.correct == 1.0;
  }
  EXPECT_GT(correct, 7);
  const auto list = cli("experiment list --db " + db);
  ASSERT_EQ(list.status, 0) << list.out;
  EXPECT_NE(list.out.find("press-side-test"), std::string::npos) << list.out;
  // The shipped CLI does not have the kind: one line, exit 2, no database.
  const auto shipped = texel::test_support::run_cli(
      TEXEL_CLI, "experiment run " + protocol_path + " --participant P01 --db " + dir.at("shipped.db") + " --simulate default");
  EXPECT_EQ(shipped.status, 2) << shipped.out;
  EXPECT_NE(shipped.out.find("task is 'press-side'; allowed: "), std::string::npos) << shipped.out;
  EXPECT_FALSE(std::filesystem::exists(dir.at("shipped.db")));
}

TEST(TaskKind, BuiltInKindsDeclareExistingExportColumns) {
  const auto columns = ex::trial_columns();
  for (const ex::TaskType* k : ex::task_types())
    for (std::string_view c : k->columns())
      EXPECT_NE(std::find(columns.begin(), columns.end(), c), columns.end()) << k->name() << ": " << c;
}

}  // namespace
