// The studies (internal; docs/experiments.md, docs/analysis.md): one
// row each — the protocol's "study" name, how analyze() summarises it and
// what its figures show. Validation (protocol.cpp), the summaries
// (analysis.cpp) and the figures (analysis_figures.cpp) read this table
// instead of comparing study names.
#pragma once

#include <span>
#include <string_view>

namespace texel::experiment {

/// How a study's rows are summarised and drawn.
enum class StudyDesign {
  staircase,     ///< thresholds per block (tracks, convergent values, paired t / RM-ANOVA)
  matching,      ///< slider matches (+ ratings): matched vs reference, ellipses
  quantization,  ///< rating changes under quantization, one-sample t-tests
  guided,        ///< guided / Bayesian matches: as matching, plus convergence and similarity
  memory,        ///< same/different under a memory load: spacing × distractor RM-ANOVA
  oddity,        ///< proportion correct per condition against chance (the 2-D oddity studies)
  playback,      ///< playback oddity: proportion correct per shift, the PSE of the dip (distributed irregularity)
};

struct Study {
  std::string_view name;   ///< the protocol's "study"
  std::string_view title;  ///< figure titles ("Texel length", …)
  StudyDesign design;
  std::string_view variable_label = {};  ///< staircase: the tracked variable's axis label
  bool blocks_by_fine_strength = false;  ///< staircase: blocks compared by their fine strength (else by name)
  bool directional = false;              ///< staircase: threshold against directional proportion
  bool ratings_figure = false;           ///< matching: the ratings' box plot
  bool direction_effects = false;        ///< oddity: each direction pair against its mode's same-direction baseline
};

/// Every study, in the order of experiments.md (the summary's key order).
std::span<const Study> studies();
/// The study named `name`, or nullptr.
const Study* find_study(std::string_view name);

}  // namespace texel::experiment
