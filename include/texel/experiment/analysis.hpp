// Per-study analysis of the long-format trial rows (records.hpp): the
// summaries and figures the thesis reports for each perceptual study
// (staircase tracks and convergent values, matched parameters with 95 %
// confidence ellipses, similarity matrices, rating changes under
// quantization per texture (repeated-measures ANOVA, one-sample t-tests),
// texel length between groups with the swipe correlations, the
// working-memory 2 × 2 repeated-measures ANOVA with the source's outlier
// rule). docs/analysis.md lists, per study, what each
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

  /// Staircase end value (docs/analysis.md): "last-presented" (default, the
  /// source's "final value": the intensity of the run's last trial) or
  /// "next" (the value computed after the last answer, never presented).
  std::string convergent = "last-presented";
  /// Procedures that stopped before their stopping rule (a staircase short
  /// of its reversals, a guided run short of its comparisons:
  /// procedure_finished never set) are reported "not finished" in the
  /// summary, the figures and the runs table, and left out of every group
  /// statistic; true puts their end value into the group statistics too
  /// (still labelled "not finished").
  bool include_unfinished = false;

  // -- working-memory outlier rule, docs/analysis.md
  /// "source" (default): main-task errors more than memory_errors_sd SDs
  /// above the group mean without more distraction-task errors than the
  /// group mean. "recall-accuracy": the earlier [choice] (recall at or below
  /// memory_recall_chance, then |z| of accuracy > memory_accuracy_sd).
  /// "none": nobody is excluded. Every rule's exclusions are reported.
  std::string memory_rule = "source";
  /// Source rule: how many SDs above the group's mean main-task error count (> 0).
  double memory_errors_sd = 2.0;
  /// Source rule [choice]: a participant is an outlier from z >=
  /// memory_errors_sd − memory_errors_sd_tolerance (z of the main-task error
  /// count). The source excluded 17 and 18 errors at mean 10.63, SD 3.36
  /// (z 1.90 and 2.19) as "near two standard deviations": its z are quoted
  /// to two digits, and 0.15 makes "near 2" reproduce both exclusions while
  /// keeping 16 errors (z 1.60) in (docs/analysis.md). 0 = the literal rule.
  double memory_errors_sd_tolerance = 0.15;
  /// "recall-accuracy" rule: exclude participants whose distractor
  /// digit-recall accuracy is at or below this proportion (chance = 1/9).
  /// Negative = that part off.
  double memory_recall_chance = 1.0 / 9.0;
  /// "recall-accuracy" rule: overall same/different accuracy more than this
  /// many SDs from the group mean (after the recall part). 0 = that part off.
  double memory_accuracy_sd = 2.5;

  // -- free exploration
  /// Confidence is related to the distance of each match from "rater"
  /// (default [choice]: the trained rater's match, for which the encoder's
  /// estimate of the reference stands in) or "group-mean" (the reference's
  /// mean match over participants).
  std::string confidence_distance = "rater";
};

/// The result of analyze().
struct AnalysisReport {
  /// JSON object text: one key per study that has (non-practice) rows, in a
  /// fixed study order; a study with no data is absent. Layout per study:
  /// docs/analysis.md.
  std::string summary = "{}";
  /// Paths of the figures written, in the order written.
  std::vector<std::string> figures;
  /// Paths of the tables written beside them (CSV, one row per procedure
  /// run: "<study>-runs.csv" with its `status` column), in the order written.
  std::vector<std::string> tables;
  /// Human-readable summary, a few lines per study, every test in the
  /// source's form: t(df) = …, p = …, 95 % CI; F(df1, df2) = …, p = …; r = …, p = ….
  std::string text;
};

/// Summarizes every study in `rows` (participants and sessions may be mixed;
/// practice rows are skipped) and, when options.out_dir is set, draws its
/// figures. A study with too few participants for a test reports that in
/// its summary ("<test>": {"skipped": "<reason>"}) instead of throwing.
/// Throws InvalidArgument for bad options (format, reversals_k, level, the
/// rule names and thresholds) and
/// IoError if a figure cannot be written.
AnalysisReport analyze(const std::vector<TrialRow>& rows, const AnalysisOptions& options);

/// The working-memory source rule's cut-off: a participant whose main-task
/// error count reaches it (and whose distraction errors did not rise) is an
/// outlier. mean + (memory_errors_sd − memory_errors_sd_tolerance) · sd.
double memory_errors_limit(double mean, double sd, const AnalysisOptions& options);

}  // namespace texel::experiment
