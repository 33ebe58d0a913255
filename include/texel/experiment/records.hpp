// The long-format trial record: one row per answered trial, the contract
// between the session store (which writes them), `texel experiment export`
// (which prints them as CSV), and the analysis (which reads them back from the
// store or from that CSV). R, pandas and MATLAB read the CSV directly:
// a header row, comma separated, RFC 4180 quoting, empty cell = missing (NA).
//
// Every field that a task does not use is missing (NaN or empty). Column
// names and units are documented in docs/session-store.md ("The export CSV").
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace texel::experiment {

inline constexpr double missing = std::numeric_limits<double>::quiet_NaN();

struct TrialRow {
  // -- who and where
  std::string participant;  ///< pseudonymous code, e.g. "S01"
  std::int64_t session_id = 0;
  std::string protocol;  ///< protocol name, e.g. "texel-length"
  std::string study;     ///< one of: working-memory, working-memory-components, texel-length, parameter-mapping,
                         ///< free-exploration, quantization, guided-exploration, coarse-features,
                         ///< direction-independence, rendering-2d, distributed-irregularity
  std::string block;     ///< block name, e.g. "narrow", "fine-50"
  int block_index = 0;   ///< 0-based position of the block in the protocol
  int trial = 0;         ///< 0-based trial index within the session (all blocks)
  int trial_in_block = 0;
  bool practice = false;
  std::string task;       ///< oddity, two-alternative, match, rating, guided, same-different, oddity-2d, playback-oddity
  std::string condition;  ///< task-specific condition label ("wide-distractor", "q3", ...); may be empty
  std::string reference;  ///< reference name (matching, rating, guided, coarse); oddity-2d: the pair's mode; may be empty

  // -- adaptive procedure (staircase tasks)
  std::string variable;             ///< adaptive variable, e.g. "texel_length_mm", "coarse_strength"
  double intensity = missing;       ///< value presented on this trial (variable's unit)
  bool reversal = false;            ///< this trial was a reversal
  double next_intensity = missing;  ///< value computed after this answer (last row: the convergent value)
  bool procedure_finished = false;  ///< the procedure finished with this answer

  // -- response
  std::string response;         ///< raw response: "2", "A", "B", "unsure", "same", "different", a rating, ...
  std::string correct_answer;   ///< what would have been correct, where there is one (never shown to participants)
  double correct = missing;     ///< 1 correct, 0 wrong, missing where the task has no right answer
  double rating = missing;      ///< similarity rating on the protocol's scale
  double confidence = missing;  ///< confidence rating (1 … 5)
  double rt_ms = missing;       ///< reaction time: first presentation → answer (ms)

  // -- matching (sliders, guided)
  double slider_p = missing;  ///< pitch slider position (protocol's slider units)
  double slider_i = missing;  ///< irregularity slider position
  double pitch_db = missing;  ///< matched / presented Central Pitch (dB re 1 cpm)
  double irregularity_db = missing;
  double pitch_a_db = missing, irregularity_a_db = missing;  ///< guided: point A
  double pitch_b_db = missing, irregularity_b_db = missing;  ///< guided: point B
  int iteration = -1;                                        ///< guided: optimizer iteration (0-based), -1 otherwise
  /// The reference's own position in (Central Pitch, Irregularity): the
  /// encoder's perceptual estimate of the reference texture (dB), so matches
  /// and references compare in one unit. Missing where there is no reference.
  double reference_pitch_db = missing;
  double reference_irregularity_db = missing;

  // -- stimulus parameters shown on this trial
  double texel_length_mm = missing;
  double coarse_strength = missing;
  double fine_strength = missing;
  double quantization_db = missing;

  // -- working memory
  double digit_cell =
      missing;  ///< matrix cell asked (0 … 15, row-major), or (verbal) sequence position asked (0-based), or missing
  double digit_response = missing;  ///< digit answered
  double digit_correct = missing;   ///< 1 / 0

  // -- swipe behaviour (docs/procedures.md §7), when a finger trace exists
  double swipe_mean_speed_mm_s = missing;
  double swipe_sd_speed_mm_s = missing;
  double directional_proportion = missing;
  // -- the finger behind the swipe columns (finger_trace.hpp); empty in rows stored before them
  std::string presentation_mode;  ///< display-plays, host-streams or passive
  std::string finger_source;      ///< display, pointer or simulated: where the trace came from
  std::string swipe_flag;         ///< why the swipe columns are empty despite a trace: no_touch, implausible_speed, …
  // -- strokes on a 2-D display (the 2-D display presenter; strokes.hpp), missing otherwise
  double strokes = missing;               ///< strokes over the trial's intervals
  double stroke_deviation_deg = missing;  ///< largest deviation of an interval's mean direction from its instructed one
  double direction_compliant = missing;   ///< 1 when every interval was stroked along its direction (within tolerance)

  // -- time stamps (UTC, ISO 8601 with milliseconds)
  std::string shown_at;
  std::string answered_at;

  // -- timing flags (docs/session-store.md "The export CSV"); missing in rows stored before them.
  // The CSV's trial_number column (1-based, what participants are shown) is trial + 1.
  double time_limit_s = missing;     ///< the trial's time limit (s), missing when none
  double over_time_limit = missing;  ///< 1 when rt_ms exceeded the time limit, 0 when not
  double interrupted = missing;      ///< 1 when the trial spanned a suspend, a stop/resume, a restart or a reload-restart
  double suspended_ms = missing;     ///< time the session was suspended during the trial (not in rt_ms)

  // -- working memory's executive distractor (n-back); missing otherwise and in rows stored before them
  double nback_targets = missing;       ///< target items in the trial's sequence
  double nback_hits = missing;          ///< targets responded to
  double nback_false_alarms = missing;  ///< non-targets responded to
};

/// The current time, UTC, ISO 8601 with milliseconds ("2026-11-23T14:02:08.123Z"):
/// the form of every time stamp in rows, events and the store.
std::string utc_timestamp();

/// Column names in CSV order (the export's header).
const std::vector<std::string>& trial_columns();
/// One CSV line (no newline) for `row`, in trial_columns() order.
std::string csv_line(const TrialRow& row);
/// The whole CSV: header + one line per row, '\n' line ends.
std::string trials_csv(const std::vector<TrialRow>& rows);
/// Reads a CSV written by trials_csv (columns may be in any order; unknown
/// columns are ignored; missing columns stay missing). Throws FormatError
/// naming the line and column.
std::vector<TrialRow> parse_trials_csv(std::string_view text, std::string_view origin);

/// The row as a JSON object of column name → cell text (the store's form;
/// same cells as the CSV), and back. Unknown keys are ignored.
std::string row_json(const TrialRow& row);
TrialRow row_from_json(std::string_view json_text, std::string_view origin);

}  // namespace texel::experiment
