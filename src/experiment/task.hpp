// Task kinds (internal; docs/experiments.md "Adding a task kind").
//
// What a task is — which block keys it reads, how many trials it plans, what
// it asks, how it scores an answer, how a simulated participant answers it
// and which export columns it fills — is owned by one TaskType per kind, in
// one file per kind (src/experiment/tasks/), listed in one table
// (tasks/table.cpp). The engine (session.cpp), the protocol parser and the
// simulated participant only look a kind up by name. Like PsychoPy's
// handler classes, a kind's running block (TaskBlock) owns both its next
// trial and the response to it.
//
// Determinism: a kind draws every random number from the SessionCore's
// counter-based streams at counters derived from the trial or block index,
// so resume (replay) rebuilds it exactly.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "texel/detail/json_fields.hpp"
#include "texel/device.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/session.hpp"
#include "texel/random.hpp"

namespace texel::experiment {

class SimulatedParticipant;

/// Counter of the engine's random streams: (major index, minor draw).
constexpr std::uint64_t draw_counter(std::uint64_t major, std::uint64_t minor) { return (major << 16) + minor; }

/// A texture template as JSON (the engine edits it per trial).
nlohmann::json texture_of(const TextureTemplate& t);
/// {"kind": "reference", "name": …, "seed": …}.
nlohmann::json reference_texture(const std::string& name, std::uint64_t seed);
/// A texel texture from a template with its seed (unless the template has
/// one) and, if given, its Central Pitch / Irregularity filled in.
nlohmann::json texel_texture(const nlohmann::json& base, std::uint64_t seed, std::optional<MatchResult> params = std::nullopt);

/// What a running block may use of its session: where it is, the random
/// streams, the stimulus documents, the references' positions and the
/// matches made so far.
struct SessionCore {
  Protocol protocol;
  SessionContext ctx;
  CounterRng order_rng;  // per-block orders and draws
  CounterRng trial_rng;  // per-trial draws
  DeviceProfile device;
  double half_mm = 0.0;  // left/right split of the matching layouts

  int block_index = 0;
  int trial = 0;
  int trial_in_block = 0;
  std::map<std::string, std::map<std::string, MatchResult>> matches;  // block → reference → match

  SessionCore(Protocol p, SessionContext c);

  [[nodiscard]] const Block& block() const { return protocol.blocks[static_cast<std::size_t>(block_index)]; }
  /// The k-th 53-bit seed of this trial (exact in JSON).
  [[nodiscard]] std::uint64_t seed_draw(std::uint64_t k) const;
  /// A uniform integer below n from this trial's stream at minor counter k.
  [[nodiscard]] std::uint64_t trial_below(std::uint64_t k, std::uint64_t n) const;
  /// Fisher–Yates of v from (seed, block): the same permutation on every resume.
  void shuffle(std::vector<int>& v) const;
  /// One stimulus document: a texture over the display (or its first length_mm).
  [[nodiscard]] std::string single(const nlohmann::json& texture, double length_mm = 0.0) const;
  /// The same on a multi-actuator device, played `playback` ("sequential" on
  /// every channel, or "simultaneous"): a document of version 6, the first
  /// with "playback" (docs/format.md).
  [[nodiscard]] std::string single_played(const nlohmann::json& texture, std::string_view playback, double length_mm = 0.0) const;
  /// The matching layout: left texture beside right texture.
  [[nodiscard]] std::string halves(const nlohmann::json& left, const nlohmann::json& right) const;
  /// The encoder's perceptual position of a reference on the protocol's device (cached).
  [[nodiscard]] MatchResult position(const std::string& reference) const;
};

/// One block being run: plans its trials when created, then prepares each
/// question and scores each answer.
class TaskBlock {
 public:
  virtual ~TaskBlock() = default;
  /// Fills the task's part of the current question and its hidden truth
  /// (the engine has set trial, block, practice, task, time limit, maps and
  /// the block's condition).
  virtual void prepare(const SessionCore& s, Question& q, TrialTruth& t) = 0;
  /// Validates `r` beyond the choices (InvalidArgument naming the field),
  /// fills the task's columns of `row`, advances the block's own state and
  /// returns the procedure state to store (JSON text).
  virtual std::string answer(SessionCore& s, const Question& q, const TrialTruth& t, const Response& r, TrialRow& row) = 0;
  /// Whether the block is over (asked after trial and trial_in_block advanced).
  [[nodiscard]] virtual bool finished(const SessionCore& s) const = 0;
  /// Slider questions: the document at these slider positions (nullopt: no sliders).
  [[nodiscard]] virtual std::optional<std::string> preview(const SessionCore&, const Question&, const TrialTruth&, double,
                                                           double) const {
    return std::nullopt;
  }
};

/// Reading a block's keys: the block object, its device, and the protocol's
/// earlier blocks (for keys that refer to them).
struct BlockInput {
  detail::JsonObject& o;
  const std::string& device;
  /// The protocol's format version: a key's default may depend on it (a
  /// version-1 protocol keeps its old meaning; docs/experiments.md "Versions").
  int version = Protocol::current_version;
  /// The texture object at `key`, validated (FormatError naming the path).
  [[nodiscard]] TextureTemplate texture(std::string_view key) const;
};

class TaskType {
 public:
  virtual ~TaskType() = default;
  /// The protocol's name of the kind ("oddity", "same-different", …).
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// The block keys this kind reads besides the common ones (name, task,
  /// practice, condition, prompt, shuffle). A key another kind reads is an
  /// error here ("does not apply to task …"); any other unknown key too.
  [[nodiscard]] virtual std::vector<std::string_view> keys() const = 0;
  /// Validate: reads this kind's keys into `b` (FormatError naming the JSON path).
  virtual void parse(BlockInput& in, Block& b) const = 0;
  /// Planned trials of a block, or nullopt when adaptive (open-ended).
  [[nodiscard]] virtual std::optional<int> planned_trials(const Block& b) const = 0;
  /// Plan: starts a block (s.block() is the block; trial_in_block is 0).
  [[nodiscard]] virtual std::unique_ptr<TaskBlock> start(const SessionCore& s) const = 0;
  /// Simulate: a simulated participant's answer (choice, rating, sliders, …)
  /// to the session's current question; the explorer's timing, events and
  /// swipe are filled in afterwards for every kind.
  virtual void simulate(const SimulatedParticipant& who, const Session& session, Response& r) const = 0;
  /// Export: the TrialRow columns (records.hpp) this kind fills beyond the
  /// ones every row has.
  [[nodiscard]] virtual std::vector<std::string_view> columns() const = 0;
  /// Whether a rating block may take this block's matches ("from_block").
  [[nodiscard]] virtual bool makes_matches() const { return false; }
  /// Whether a stored row of this kind holds a finished match (pitch_db,
  /// irregularity_db), which later sessions' ratings may use ("from_protocol").
  [[nodiscard]] virtual bool holds_match(const TrialRow&) const { return false; }
};

/// The kind named `name`; FormatError naming `field` and the known kinds.
const TaskType& task_type(std::string_view name, std::string_view field = "task");
/// Adds a kind to the table (tests add test-only kinds this way); throws
/// InvalidArgument if the name is taken.
void register_task(std::unique_ptr<TaskType> type);
/// Every kind, in table order.
std::vector<const TaskType*> task_types();
/// The kind named `name`, or nullptr (rows stored by kinds this build lacks).
const TaskType* find_task_type(std::string_view name);

/// The common columns' helper: the numeric key of the block's texture.
double template_number(const Block& b, const char* key);
/// A three-interval oddity question's words and answer, one for every
/// oddity task (threshold, 2-D oddity, playback oddity): choices "1" … "3",
/// "The odd one is", the block's prompt or the source's; the correct answer
/// is the odd interval's number (`odd` 0-based).
void ask_oddity(const Block& b, int odd, Question& q, TrialTruth& t);
/// "a, b, c".
std::string joined(const std::vector<std::string>& items);
/// InvalidArgument(msg) unless ok.
void require(bool ok, const std::string& msg);
/// Validates a reference name (FormatError naming `path`, listing the catalogue).
void check_reference(const std::string& name, const std::string& path);
/// A JSON array of strings at `key` with min_count … 4096 entries.
std::vector<std::string> string_list(detail::JsonObject& o, std::string_view key, std::size_t min_count);

}  // namespace texel::experiment
