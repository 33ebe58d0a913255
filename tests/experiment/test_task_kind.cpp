// A task kind added the way docs/experiments.md "Adding a task kind" says —
// one type (below) and one registration — runs end to end: validated in a
// protocol, run by simulated participants and stored (the library path
// `texel experiment run --simulate` takes), exported as CSV, and run through
// the studio's experiment messages (texel::studio::Service). The built-in
// kinds' declared export columns all exist.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>

#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "task.hpp"
#include "texel/error.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/runner.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/experiment/store.hpp"
#include "texel/studio/service.hpp"

namespace ex = texel::experiment;
using json = nlohmann::json;

namespace {

// ------------------------------------------------- the test-only task kind
// "press-side": a texture on the left or the right half; which side is it?
// Its one setting ("presses", the trial count) lives in its own settings type.

struct PressSettings : ex::TaskSettings {
  int presses = 0;
};

int presses(const ex::Block& b) { return static_cast<const PressSettings&>(*b.settings).presses; }

class PressBlock : public ex::TaskBlock {
 public:
  void prepare(const ex::SessionCore& s, ex::Question& q, ex::TrialTruth& t) override {
    const ex::Block& b = s.block();
    q.block_trials = presses(b);
    const bool left = s.trial_below(0, 2) == 0;
    const json texture = ex::texel_texture(ex::texture_of(b.texture), s.seed_draw(1));
    const json flat = {
        {"kind", "texel"}, {"seed", 1}, {"texel_length_mm", 5.0}, {"central_pitch_db", 0.0}, {"irregularity_db", -20.0}};
    q.stimuli.push_back({"Surface", s.halves(left ? texture : flat, left ? flat : texture)});
    q.choices = {"left", "right"};
    q.prompt = "Which half is textured?";
    t.correct_answer = left ? "left" : "right";
  }
  std::string answer(ex::SessionCore&, const ex::Question&, const ex::TrialTruth& t, const ex::Response& r,
                     ex::TrialRow& row) override {
    row.correct = r.choice == t.correct_answer ? 1.0 : 0.0;
    return "{}";
  }
  bool finished(const ex::SessionCore& s) const override { return s.trial_in_block >= presses(s.block()); }
};

class PressTask : public ex::TaskType {
 public:
  std::string_view name() const override { return "press-side"; }
  std::vector<std::string_view> keys() const override { return {"texture", "presses"}; }
  void parse(ex::BlockInput& in, ex::Block& b) const override {
    b.texture = in.texture("texture");
    auto settings = std::make_shared<PressSettings>();
    settings->presses = static_cast<int>(in.o.integer("presses", 1, 100));
    b.settings = std::move(settings);
  }
  std::optional<int> planned_trials(const ex::Block& b) const override { return presses(b); }
  std::unique_ptr<ex::TaskBlock> start(const ex::SessionCore&) const override { return std::make_unique<PressBlock>(); }
  void simulate(const ex::SimulatedParticipant& who, const ex::Session& session, ex::Response& r) const override {
    const auto trial = static_cast<std::uint64_t>(session.question().trial);
    const bool ok = who.behaviour().uniform(trial * 8 + 2) < 0.9;
    r.choice = ok ? session.truth().correct_answer : who.wrong_choice(session.question(), session.truth().correct_answer);
  }
  std::vector<std::string_view> columns() const override { return {"response", "correct_answer", "correct"}; }
};

// The one registration (a library kind is one row in tasks/table.cpp instead).
const bool registered = [] {
  ex::register_task(std::make_unique<PressTask>());
  return true;
}();

const std::string protocol_text = R"({
  "format": "texel-protocol", "version": 1, "name": "press-side-test", "study": "working-memory",
  "device": "tpad", "seed": 7,
  "blocks": [
    {"name": "warm-up", "task": "press-side", "practice": true, "presses": 2,
     "texture": {"kind": "texel", "texel_length_mm": 4, "central_pitch_db": 6, "irregularity_db": -6}},
    {"name": "main", "task": "press-side", "presses": 5,
     "texture": {"kind": "texel", "texel_length_mm": 6, "central_pitch_db": 6, "irregularity_db": -6}}
  ]
})";

TEST(TaskKind, TestOnlyKindIsValidatedLikeABuiltInOne) {
  ASSERT_TRUE(registered);
  const auto names = ex::task_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "press-side"), names.end());
  const ex::Protocol p = ex::parse_protocol(protocol_text);
  EXPECT_EQ(p.planned_trials(), 7);
  auto message = [](const std::string& from, const std::string& to) {
    std::string text = protocol_text;
    text.replace(text.find(from), from.size(), to);
    try {
      (void)ex::parse_protocol(text);
    } catch (const texel::FormatError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
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

// Replies of a Service client.
struct Inbox {
  std::mutex m;
  std::condition_variable cv;
  std::vector<json> replies;
  json wait_for(int id) {
    std::unique_lock lock(m);
    json out;
    const bool found = cv.wait_for(lock, std::chrono::seconds(60), [&] {
      for (auto it = replies.begin(); it != replies.end(); ++it)
        if (it->contains("id") && (*it)["id"] == id) {
          out = *it;
          replies.erase(it);
          return true;
        }
      return false;
    });
    if (!found) ADD_FAILURE() << "no reply to message " << id;
    return out;
  }
};

TEST(TaskKind, TestOnlyKindRunsThroughTheStudio) {
  texel::test_support::TempDir dir("task-kind-studio");
  texel::studio::ServiceOptions o;
  o.db_path = dir.at("s.db");
  texel::studio::Service service(o);
  Inbox inbox;
  const auto client = service.connect([&](std::string text) {
    std::lock_guard lock(inbox.m);
    inbox.replies.push_back(json::parse(text));
    inbox.cv.notify_all();
  });
  int next = 1;
  auto ask = [&](json msg) {
    const int id = next++;
    msg["id"] = id;
    service.handle(client, msg.dump());
    return inbox.wait_for(id);
  };
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
  service.disconnect(client);
}

TEST(TaskKind, BuiltInKindsDeclareExistingExportColumns) {
  const auto columns = ex::trial_columns();
  for (const ex::TaskType* k : ex::task_types())
    for (std::string_view c : k->columns())
      EXPECT_NE(std::find(columns.begin(), columns.end(), c), columns.end()) << k->name() << ": " << c;
}

}  // namespace
