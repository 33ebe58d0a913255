// Protocol files: an experiment is data, not code (docs/procedures.md §6; format in
// docs/experiments.md, schema in docs/schema/texel-protocol.schema.json).
//
// A protocol names its study, a device, a randomization seed, the simulated
// observer that `--simulate default` uses, and an ordered list of blocks.
// Each block runs one task kind — oddity, two-alternative, match, rating,
// guided, same-different — with its stimuli, timings, response type and (for
// the threshold tasks) a staircase. What a task kind is (its keys, plan,
// questions, scoring, simulated answers, export columns) is owned by one
// type per kind in src/experiment/tasks/, registered in one table
// (docs/experiments.md "Adding a task kind"). Validation names the field by
// its JSON path, the value and what is allowed; unknown keys are errors, so
// a misspelt key never falls back to a default.
//
// Trade-off: the built-in kinds' settings stay one flat Block type (read per
// kind) rather than a settings class per kind, so a front end can show any
// block's settings; a kind added later keeps its own in Block::settings.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "texel/experiment/guided.hpp"
#include "texel/experiment/staircase.hpp"

namespace texel::experiment {

/// The task kinds a protocol may name ("oddity", "two-alternative", …), in
/// the order of the task table.
std::vector<std::string> task_names();

/// A validated texture template: a document "texture" object (kind texel
/// unless it says otherwise; the seed may be missing, the engine draws one
/// per trial), kept as its JSON text.
struct TextureTemplate {
  std::string json;  ///< JSON object text; empty = none
  [[nodiscard]] bool empty() const { return json.empty(); }
  /// The template's number at `key` (e.g. "fine_strength"), if it has one.
  [[nodiscard]] std::optional<double> number(std::string_view key) const;
};

/// Settings of a task kind that are not fields of Block (kinds added after
/// the built-in ones derive from this; see docs/experiments.md).
struct TaskSettings {
  virtual ~TaskSettings() = default;
};

/// The studies (a protocol's "study"): the seven of docs/procedures.md §6, then the 2-D ones.
std::vector<std::string> study_names();

/// Slider mappings of the matching studies.
enum class SliderMapping {
  lognormal,  ///< study 2: P 0…100 → m = 0.75·1.04^P cpm, I 0…100 → s = 3·I/10 cpm (moments)
  device_db,  ///< study 3: sliders in dB over the device ranges (−20…19.7, −30…5)
};

/// A rendering shown on the right in a rating trial.
struct RenderingSource {
  TextureTemplate texture;       ///< explicit texel texture; may be empty
  std::string match_of;          ///< use the match of this reference …
  std::string from_block;        ///< … made in this block of the same session
  std::string from_protocol;     ///< … or in the participant's finished session of this protocol
  double quantization_db = 0.0;  ///< applied to the rendering (0 = unquantized)
};

struct RatingPair {
  std::string reference;  ///< reference felt on the left
  RenderingSource rendering;
  std::string condition;  ///< label for the analysis ("unquantized", "q3", "rendering:4sin", …)
};

/// Working memory: the component of working memory a distractor task loads
/// (docs/experiments.md "Working-memory components").
enum class MemoryComponent {
  visuospatial,  ///< the source's 4 × 4 digit matrix (control: every cell holds 1)
  verbal,        ///< a digit sequence to hold in order (control: every digit is 1)
  executive,     ///< 2-back on a digit stream (control: 0-back, respond to every 1)
};
std::string_view to_string(MemoryComponent c);
/// "visuospatial" | "verbal" | "executive"; FormatError naming `field` otherwise.
MemoryComponent parse_memory_component(std::string_view text, std::string_view field);

/// Working memory: one condition (texture × distractor).
struct MemoryCondition {
  std::string name;        ///< e.g. "wide-distractor"; the analysis reads "<texture>-<distractor>"
  std::string stimulus;    ///< key into Block::memory_stimuli
  bool distractor = true;  ///< false: the component's control task (same display and timing, no load)
  MemoryComponent component = MemoryComponent::visuospatial;
};
struct MemoryStimulus {
  std::string name;
  TextureTemplate texture;    ///< texture 1
  TextureTemplate different;  ///< texture 2 on "different" trials
};

/// A named texture of a familiarisation block.
struct NamedTexture {
  std::string name;  ///< the button's label
  TextureTemplate texture;
};

struct Block {
  std::string name;
  std::string task = "oddity";  ///< a name of task_names()
  bool practice = false;
  std::string condition;  ///< label copied to every row ("narrow", "fine-50", …)
  std::string prompt;     ///< participant-facing instruction (empty: the task's default)

  // Stimulus layout.
  double display_mm = 0.0;    ///< oddity / two-alternative: textured length from 0 (0 = the whole device)
  double time_limit_s = 0.0;  ///< 0 = none (oddity: 30 s)
  bool show_maps = false;     ///< visual practice: the front end draws the friction maps
  TextureTemplate texture;    ///< base texel texture (seed optional)

  // Adaptive (oddity, two-alternative).
  std::optional<StaircaseConfig> staircase;
  std::string variable;      ///< texture key the staircase sets, e.g. "texel_length_mm"
  int trials = 0;            ///< fixed trial count when there is no staircase (practice)
  double fixed_value = 0.0;  ///< value of `variable` without a staircase

  // References (two-alternative: the pair A/B; match, guided: the list).
  std::vector<std::string> references;
  bool shuffle = true;  ///< randomize the order of references / pairs / trials

  // Match.
  SliderMapping sliders = SliderMapping::device_db;
  bool confidence = false;  ///< ask a 1…5 confidence rating after each match

  // Rating.
  double scale_min = 1.0, scale_max = 5.0;
  std::vector<RatingPair> pairs;
  int repeats = 1;

  // Guided.
  OptimizerKind optimizer = OptimizerKind::guided;
  std::string optimizer_params = "{}";  ///< the optimizer's keys (JSON object text, without "kind")

  // Same-different.
  std::vector<MemoryCondition> conditions;
  std::vector<MemoryStimulus> memory_stimuli;
  int trials_per_condition = 8;
  double texture_s = 10.0, matrix_s = 10.0;
  int matrix_cells = 5;
  int sequence_length = 5;  ///< verbal: digits in the sequence, 1 … 9 (distinct), shown matrix_s / length each
  int nback_items = 10;     ///< executive: digits in the stream, 4 … 30, shown matrix_s / items each
  int nback_targets = 3;    ///< executive: targets in the stream, 1 … nback_items − 2
  bool recall_question = true;
  bool balance_order = false;  ///< draw per trial which stimulus texture comes first (and is repeated on "same")
  /// `base_textures` "per-texture": each stimulus texture (a `patch-*`
  /// reference) has one gap set per session and every presentation is a
  /// rearrangement of it (the source's 64 textures); false ("per-trial",
  /// the default): a new gap set every trial.
  bool base_per_texture = false;

  // Familiarisation.
  std::vector<NamedTexture> textures;
  double duration_s = 300.0;  ///< the suggested time, shown in the prompt (untimed)

  /// A kind's own settings (nullptr for the built-in kinds).
  std::shared_ptr<const TaskSettings> settings;
};

struct Protocol {
  /// 1: the first format (its defaults kept exactly, so stored sessions
  /// replay); 2: the source-faithful defaults (staircase end value and start
  /// rule) and checks (docs/experiments.md "Protocol versions").
  static constexpr int current_version = 3;
  int version = current_version;
  std::string name;
  std::string study;
  std::string title;
  std::string description;
  std::string device = "tpad";
  std::uint64_t seed = 1;
  /// What a reload of a participant screen does to the trial on it:
  /// "keep_clock" (default: same token, onset kept) or "restart_trial" (runner.hpp ReloadRule).
  std::string on_reload = "keep_clock";
  std::string observer = "{}";  ///< simulated observer for `--simulate default` (JSON object text)
  std::vector<Block> blocks;
  std::string json;  ///< the validated source (stored with every session)

  [[nodiscard]] const Block* block(std::string_view name) const;
  /// Trials the protocol will run, or -1 when a staircase makes it open-ended.
  [[nodiscard]] int planned_trials() const;
};

/// Parses and validates; `origin` names the source in errors.
Protocol parse_protocol(std::string_view json_text, std::string_view origin = "protocol");
Protocol load_protocol(const std::string& path);

}  // namespace texel::experiment
