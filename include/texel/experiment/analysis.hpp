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
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "texel/experiment/records.hpp"
#include "texel/option_spec.hpp"

namespace texel::experiment {

/// Figure file format.
enum class FigureFormat { png, svg };
/// A staircase's end value: the intensity of its last trial (the source's
/// "final value") or the value computed after its last answer (never presented).
enum class ConvergentValue { last_presented, next };
/// The working-memory outlier rule (docs/analysis.md).
enum class MemoryRule { source, recall_accuracy, none };
/// What free-exploration confidence is related to: the distance to the
/// trained rater's match or to the reference's group-mean match.
enum class ConfidenceDistance { rater, group_mean };

inline constexpr OptionChoice figure_formats[] = {{"png", 0}, {"svg", 1}};
inline constexpr OptionChoice convergent_values[] = {{"last-presented", 0}, {"next", 1}};
inline constexpr OptionChoice memory_rules[] = {{"source", 0}, {"recall-accuracy", 1}, {"none", 2}};
inline constexpr OptionChoice confidence_distances[] = {{"rater", 0}, {"group-mean", 1}};

/// The spellings the front doors and the summary JSON use: "png", "last-presented", "recall-accuracy", "group-mean".
std::string_view to_string(FigureFormat f);
std::string_view to_string(ConvergentValue c);
std::string_view to_string(MemoryRule r);
std::string_view to_string(ConfidenceDistance d);

/// How analyze() summarizes and what it draws.
struct AnalysisOptions {
  /// Directory the figures are written to (created if missing); empty = no
  /// figures. Files are named "<study>-<figure>.<format>".
  std::string out_dir;
  /// Figure format.
  FigureFormat format = FigureFormat::png;
  /// Staircase threshold = mean intensity of the last k reversals (1 … 1000);
  /// fewer reversals than k: the mean of all of them (reported with their count).
  std::size_t reversals_k = 6;
  /// Confidence level of the CIs, t-tests and ellipses, in (0, 1).
  double level = 0.95;

  /// Staircase end value (docs/analysis.md): last_presented (default, the
  /// source's "final value": the intensity of the run's last trial) or
  /// next (the value computed after the last answer, never presented).
  ConvergentValue convergent = ConvergentValue::last_presented;
  /// Procedures that stopped before their stopping rule (a staircase short
  /// of its reversals, a guided run short of its comparisons:
  /// procedure_finished never set) are reported "not finished" in the
  /// summary, the figures and the runs table, and left out of every group
  /// statistic; true puts their end value into the group statistics too
  /// (still labelled "not finished").
  bool include_unfinished = false;

  // -- working-memory outlier rule, docs/analysis.md
  /// source (default): main-task errors more than memory_errors_sd SDs
  /// above the group mean without more distraction-task errors than the
  /// group mean. recall_accuracy: the earlier [choice] (recall at or below
  /// memory_recall_chance, then |z| of accuracy > memory_accuracy_sd).
  /// none: nobody is excluded. Every rule's exclusions are reported.
  MemoryRule memory_rule = MemoryRule::source;
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
  /// Confidence is related to the distance of each match from the rater's
  /// (default [choice]: the trained rater's match, for which the encoder's
  /// estimate of the reference stands in) or the group mean (the reference's
  /// mean match over participants).
  ConfidenceDistance confidence_distance = ConfidenceDistance::rater;
};

/// Every option of AnalysisOptions but out_dir, described once for the
/// front doors (texel/option_spec.hpp): `visit(member, spec)` per option.
template <class Options, class Visit>
requires std::is_same_v<std::remove_const_t<Options>, AnalysisOptions>
void visit_options(Options& o, Visit&& visit) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  visit(o.format, OptionSpec{"format", "format", "Figure format: png or svg", -inf, inf, false, false, figure_formats});
  visit(o.reversals_k, OptionSpec{"reversals_k", "reversals", "Staircase threshold = mean of the last K reversals", 1, 1000});
  visit(o.level, OptionSpec{"level", "level", "Confidence level of the CIs, t-tests and ellipses", 0, 1, true, true});
  visit(o.convergent, OptionSpec{"convergent", "convergent",
                                 "Staircase end value: last-presented (the source's final value) or next (computed after "
                                 "the last answer)",
                                 -inf, inf, false, false, convergent_values});
  visit(o.include_unfinished, OptionSpec{"include_unfinished", "include-unfinished",
                                         "Put procedures that stopped before their stopping rule into the group "
                                         "statistics (still reported \"not finished\")"});
  visit(o.memory_rule, OptionSpec{"memory_rule", "memory-rule",
                                  "Working-memory outliers: source (errors above mean + k SD without more distraction "
                                  "errors), recall-accuracy (the earlier rule) or none",
                                  -inf, inf, false, false, memory_rules});
  visit(o.memory_errors_sd, OptionSpec{"memory_errors_sd", "memory-errors-sd", "Working memory, source rule: k", 0, inf, true});
  visit(o.memory_errors_sd_tolerance,
        OptionSpec{"memory_errors_sd_tolerance", "memory-errors-sd-tolerance",
                   "Working memory, source rule: an outlier from z >= k minus this (\"near\" k SD; 0 = literal; below k)", 0});
  visit(o.memory_recall_chance, OptionSpec{"memory_recall_chance", "memory-recall-chance",
                                           "Working memory, recall-accuracy rule: digit recall at or below this; "
                                           "negative = off",
                                           -inf, 1, false, true});
  visit(o.memory_accuracy_sd, OptionSpec{"memory_accuracy_sd", "memory-accuracy-sd",
                                         "Working memory, recall-accuracy rule: this many SD from the group's accuracy; "
                                         "0 = off",
                                         0});
  visit(o.confidence_distance, OptionSpec{"confidence_distance", "confidence-distance",
                                          "Free exploration: confidence against the distance to the rater's match (the "
                                          "encoder's estimate) or to the group-mean match",
                                          -inf, inf, false, false, confidence_distances});
}

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
/// IoError if a figure cannot be written. The figures and tables are drawn
/// into a hidden folder inside out_dir and moved in only once all are drawn:
/// a failure leaves none of this run's files, nor an out_dir it created.
AnalysisReport analyze(const std::vector<TrialRow>& rows, const AnalysisOptions& options);

/// The working-memory source rule's cut-off: a participant whose main-task
/// error count reaches it (and whose distraction errors did not rise) is an
/// outlier. mean + (memory_errors_sd − memory_errors_sd_tolerance) · sd.
double memory_errors_limit(double mean, double sd, const AnalysisOptions& options);

}  // namespace texel::experiment
