// The experiment engine: a protocol in, one question at a time out, answers
// in, records to store out. No terminal, network or file I/O inside: the
// terminal runner (`texel experiment run`), the studio and the Python
// bindings all drive this same object (docs/contributing.md §5: "a procedure is a state
// machine you step").
//
//   Session s(protocol, context);
//   while (!s.finished()) {
//     const Question& q = s.question();     // what to show (never the answer)
//     ... present q.stimuli, collect a Response ...
//     StoredTrial t = s.answer(response);   // validated; the engine advances
//     store.append_trial(lock, t);          // commit before the next question
//   }
//
// Determinism and resume. Every random draw of a trial (seeds of the
// stimuli, the odd interval, orders, matrix digits) comes from
// CounterRng(session seed, stream) at a counter derived from the trial index
// or block index, and every adaptive procedure is rebuilt by replaying its
// answers. So resume is replay: a Session built from the same protocol and
// seed, fed the stored responses with `replay()`, is in exactly the state an
// uninterrupted run would be in (and `replay` checks that the stored question
// is the one it would have asked).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "texel/experiment/guided.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/staircase.hpp"
#include "texel/experiment/store.hpp"
#include "texel/experiment/strokes.hpp"

namespace texel::experiment {

/// How an interval plays on a 2-D display the participant strokes (the
/// 2-D display presenter, presenter.hpp): the surface and the direction the
/// participant is asked to stroke along. Engine-side only: not part of the
/// question's JSON views (the stored question keeps its bytes).
struct SurfaceStimulus {
  enum class Kind { path_indexed, bitmap };
  Kind kind = Kind::path_indexed;  ///< path-indexed texture, or the friction bitmap of a static field
  std::string document_json;       ///< a version-4 document of one region covering the display
  double direction_deg = 0.0;      ///< the stroke direction asked for (surface coordinates)
};

/// Something the participant can select and feel.
struct Stimulus {
  std::string label;          ///< button text: "1", "Reference", "A", "Test", "Texture 1", …
  std::string document_json;  ///< the full texture document (device, regions)
};

/// One timed phase of a trial (working memory): show a stimulus, the digit
/// matrix, or the digit sequence (Question::sequence, one digit at a time,
/// each for duration_s / its length), for a fixed time.
enum class PhaseKind { stimulus, matrix, sequence };
std::string_view to_string(PhaseKind k);  ///< "stimulus" | "matrix" | "sequence"
struct Phase {
  PhaseKind kind = PhaseKind::stimulus;
  std::optional<int> stimulus;  ///< index into Question::stimuli (stimulus phases)
  double duration_s = 0.0;
};

/// Working memory's recall question after the same/different answer.
/// The matrix (visuospatial) asks for a cell; the digit sequence (verbal)
/// for a position.
struct RecallQuestion {
  std::optional<int> cell;  ///< the cell asked (0 … 15, row-major); nullopt = "the digit in the cells" (control)
  /// Sequence recall: the position asked (0-based); nullopt with a sequence =
  /// "the digit of the sequence" (control: every digit is 1).
  std::optional<int> position;
};

/// Working memory's executive distractor: while Question::sequence is shown
/// the participant responds (a key, a button) to each target digit — a digit
/// equal to the one `n` before it (2-back), or with n = 0 every `target`
/// digit (0-back, the control: attention without updating).
struct NBackTask {
  int n = 2;       ///< 0 (control) or 1 … 3
  int target = 0;  ///< n = 0: the target digit 1 … 9; 0 otherwise
};

struct SliderSpec {
  std::string name;   ///< "pitch" | "irregularity"
  std::string label;  ///< participant-facing
  double min = 0.0, max = 100.0, start = 50.0;
};

/// A numbered scale a participant answers on, in whole steps: what it asks
/// and the words at its two ends.
struct Scale {
  int min = 1, max = 5;
  std::string question;   ///< "How confident are you in this match?"
  std::string min_label;  ///< words at `min`: "not at all" ("" = none)
  std::string max_label;  ///< words at `max`: "very"
};

/// Everything a participant reads for one question besides the prompt,
/// worded once here so every front door (terminal, studio page) asks the
/// same: the front doors only lay it out. Not part of the stored question.
struct Wording {
  std::vector<std::string> stimulus_names;  ///< per stimulus, as a sentence names it: "texture 1", "the reference"
  std::string choice_question;              ///< heading of the choice ("The odd one is"); "" when no choice is asked
  std::vector<std::string> choice_labels;   ///< per Question::choices entry, the words shown: "texture 1", "Same"
  std::optional<Scale> rating;              ///< the similarity scale (Question::rating_scale)
  std::optional<Scale> confidence;          ///< the confidence scale (Question::confidence)
  std::optional<Scale> recall;              ///< working memory's digit question, the cell in words
  /// Working memory's sequence phase: what to do with the digits ("Remember
  /// these digits in their order.", "Respond whenever …"); "" otherwise.
  std::string sequence_instruction;
};

/// How sentences name a stimulus of this label: "1" → "texture 1", "Test" →
/// "the test texture", "Reference | Rendering" → "the reference (left half)
/// and the rendering (right half)".
std::string stimulus_name(const std::string& label);

/// What a front end shows for the current trial. Holds nothing that would
/// reveal the answer.
struct Question {
  int trial = 0;  ///< 0-based index in the session
  int block_index = 0;
  std::string block;
  int trial_in_block = 0;
  std::optional<int> block_trials;  ///< planned trials in this block; nullopt = adaptive
  bool practice = false;
  std::string task;  ///< the block's task kind
  std::string prompt;
  std::vector<Stimulus> stimuli;
  /// On a 2-D display (oddity-2d): what plays while the participant strokes
  /// stimulus i is surfaces[i]; empty for every other task.
  std::vector<SurfaceStimulus> surfaces;
  std::vector<std::string> choices;                   ///< allowed Response::choice values (empty: none asked)
  std::optional<std::array<double, 2>> rating_scale;  ///< [min, max], whole steps
  std::vector<SliderSpec> sliders;
  bool confidence = false;                    ///< ask a 1 … 5 confidence rating
  double time_limit_s = 0.0;                  ///< 0 = none
  bool show_maps = false;                     ///< visual practice: draw the stimuli's friction maps
  std::vector<Phase> phases;                  ///< timed sequence before the questions (working memory)
  std::optional<std::array<int, 16>> matrix;  ///< working memory: 4 × 4 digits, 0 = empty cell
  std::optional<RecallQuestion> recall;       ///< working memory: the digit question, if asked
  /// Working memory (verbal, executive): the digits shown one at a time
  /// during the sequence phase (1 … 9); empty otherwise.
  std::vector<int> sequence;
  std::optional<NBackTask> nback;  ///< working memory (executive): respond to targets during the sequence
  /// What the participant reads (the task kind words choice_question and the
  /// scales' labels where it has its own; the engine fills the rest).
  Wording wording;

  /// The engine's JSON view (JSON text; stored with every trial, so its bytes
  /// are part of the store format: docs/format.md "Result field names").
  [[nodiscard]] std::string to_json() const;
  /// What a participant's screen may see: to_json() without the block (name,
  /// index, place in it) and without the stimulus documents (their parameters
  /// would give the odd one away, their seeds are the session's), with
  /// "wording" (Wording); a front end that draws a show_maps question's maps
  /// sends the rendered maps.
  [[nodiscard]] std::string participant_json() const;
};

/// A participant's answer. Only the fields the question asks for are read.
struct Response {
  std::string choice;                        ///< one of Question::choices
  std::optional<double> rating;              ///< on Question::rating_scale
  std::optional<double> confidence;          ///< 1 … 5
  std::optional<double> slider_p, slider_i;  ///< final slider positions
  std::optional<int> digit;                  ///< recall answer 1 … 9
  /// Executive distractor: the sequence items (0-based) at which the
  /// participant responded, increasing; the front end maps a response to the
  /// digit on screen at that moment.
  std::vector<int> presses;
  double rt_ms = missing;          ///< first presentation → answer
  std::vector<TrialEvent> events;  ///< presentation / selection events
  std::optional<double> swipe_mean_speed_mm_s, swipe_sd_speed_mm_s, directional_proportion;
  /// Why a finger trace gave no swipe measures (TraceMeasures::flag in
  /// finger_trace.hpp); empty when they are stored or there was no trace.
  std::string swipe_flag;
  /// A 2-D display's strokes, one entry per interval felt (strokes.hpp); fills
  /// the row's stroke columns.
  std::vector<IntervalStrokes> strokes;
  /// The finger that explored the trial (a display's reports, the studio's
  /// pointer, or the simulated finger), stored with the trial. A display's
  /// or pointer's trace fills the swipe columns (its measures replace the
  /// three fields above); a simulated one only where they are unset.
  /// Not part of to_json() (the store keeps it in a table of its own).
  FingerTrace trace;
  std::string shown_at, answered_at;  ///< ISO 8601 UTC

  [[nodiscard]] std::string to_json() const;  ///< JSON text (stored with every trial)
  /// Parses a front end's answer (JSON object text); throws FormatError naming the field.
  static Response from_json(std::string_view json_text);
};

/// A finished match (slider or guided), by reference.
struct MatchResult {
  double pitch_db = 0.0;
  double irregularity_db = 0.0;
};

struct SessionContext {
  std::string participant;
  std::int64_t session_id = 0;
  std::uint64_t seed = 0;  ///< randomization seed (protocol seed mixed with the participant code by default)
  /// Matches from the participant's earlier finished sessions, by protocol
  /// then reference (for rating renderings "from_protocol"). Resolved when
  /// the session is created and stored with it, so resume sees the same.
  std::map<std::string, std::map<std::string, MatchResult>> prior_matches;
};

/// The seed a participant's session uses by default: the protocol's seed
/// mixed with the participant code, so participants get different draws and
/// a re-run of the same participant the same ones.
std::uint64_t session_seed(std::uint64_t protocol_seed, const std::string& participant);

/// The hidden side of the current trial (for simulated observers, stored
/// with the trial, never shown to participants).
struct TrialTruth {
  std::string correct_answer;            ///< "" where there is none
  double intensity = missing;            ///< staircase / fixed value of the block's variable
  std::string reference;                 ///< reference felt
  std::optional<MatchResult> rendering;  ///< parameters of the compared rendering (rating)
  double quantization_db = 0.0;
  std::optional<MatchQuestion> pair;  ///< guided: the two points
  std::string condition;
};

class Session {
 public:
  /// Prepares the first question. Throws FormatError/InvalidArgument for a
  /// protocol the engine cannot run.
  Session(Protocol protocol, SessionContext context);
  ~Session();
  Session(Session&&) noexcept;
  Session& operator=(Session&&) noexcept;

  [[nodiscard]] bool finished() const;
  /// The current question; throws texel::Error when finished.
  [[nodiscard]] const Question& question() const;
  [[nodiscard]] const TrialTruth& truth() const;
  /// For match questions: the document to feel at these slider positions.
  [[nodiscard]] std::string preview_document(double slider_p, double slider_i) const;
  /// Validates `r` against the question (InvalidArgument naming the field),
  /// advances, and returns the record to store.
  StoredTrial answer(const Response& r);
  /// Re-applies a stored trial (resume): checks that it answers the question
  /// this session would ask now, then answers it. Throws FormatError if the
  /// stored data do not fit (another protocol, seed or engine version).
  void replay(const StoredTrial& t);

  [[nodiscard]] int trials_done() const;
  [[nodiscard]] int trials_planned() const;  ///< -1 when adaptive
  [[nodiscard]] const Protocol& protocol() const;
  [[nodiscard]] const SessionContext& context() const;
  /// Matches finished so far in a block, by reference.
  [[nodiscard]] std::map<std::string, MatchResult> matches(const std::string& block) const;
  /// The encoder's perceptual position of a reference on the protocol's device (cached).
  [[nodiscard]] MatchResult reference_position(const std::string& reference) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Slider mappings (docs/procedures.md §6, studies 2 and 3): slider positions to
/// (Central Pitch dB, Irregularity dB) under the moments parameterization.
MatchResult slider_to_parameters(SliderMapping mapping, double slider_p, double slider_i);

}  // namespace texel::experiment
