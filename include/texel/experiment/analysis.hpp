// Per-study analysis of the long-format trial rows (records.hpp): the
// summaries and figures the thesis reports for each perceptual study
// (staircase tracks and convergent values, matched parameters with 95 %
// confidence ellipses, similarity matrices, rating changes under
// quantization with one-sample t-tests, the working-memory 2 × 2
// repeated-measures ANOVA). docs/analysis.md lists, per study, what each
// summary and figure answers and the [choice]s made where the source is
// silent (threshold estimate, outlier rule).
//
// One front door: `texel experiment analyze`, the studio and the bindings
// all call analyze(). It is a pure function of the rows and the options
// apart from the figure files it writes; statistics come from stats.hpp.
// Trade-off: summaries are plain JSON text (keys in a fixed order) rather
// than typed structs, so the CLI, the studio and R read the same document and
// a new measure is one more key, not an ABI change.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "texel/experiment/records.hpp"

namespace texel::experiment {

/// How analyze() summarizes and what it draws.
struct AnalysisOptions {
  /// Directory the figures are written to (created if missing); empty = no
  /// figures. Files are named "<study>-<figure>.<format>".
  std::string out_dir;
  /// Figure format: "png" or "svg".
  std::string format = "png";
  /// Staircase threshold = mean intensity of the last k reversals (>= 1);
  /// fewer reversals than k: the mean of all of them (reported with their count).
  std::size_t reversals_k = 6;
  /// Confidence level of the CIs, t-tests and ellipses, in (0, 1).
  double level = 0.95;

  // -- working-memory outlier rule [choice], docs/analysis.md
  /// Exclude participants whose distractor digit-recall accuracy is at or
  /// below this proportion (chance = 1/9: they ignored the distractor).
  /// Negative = rule off.
  double memory_recall_chance = 1.0 / 9.0;
  /// Exclude participants whose overall same/different accuracy lies more
  /// than this many SDs from the group mean (computed once, on the
  /// participants left after the recall rule). 0 = rule off.
  double memory_accuracy_sd = 2.5;
};

/// The result of analyze().
struct AnalysisReport {
  /// JSON object text: one key per study that has (non-practice) rows, in a
  /// fixed study order; a study with no data is absent. Layout per study:
  /// docs/analysis.md.
  std::string summary = "{}";
  /// Paths of the figures written, in the order written.
  std::vector<std::string> figures;
  /// Human-readable summary (a few lines per study).
  std::string text;
};

/// Summarizes every study in `rows` (participants and sessions may be mixed;
/// practice rows are skipped) and, when options.out_dir is set, draws its
/// figures. A study with too few participants for a test reports that in
/// its summary ("<test>": {"skipped": "<reason>"}) instead of throwing.
/// Throws InvalidArgument for bad options (format, reversals_k, level) and
/// IoError if a figure cannot be written.
AnalysisReport analyze(const std::vector<TrialRow>& rows, const AnalysisOptions& options);

}  // namespace texel::experiment
