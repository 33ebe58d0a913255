// The analysis figures (internal; analysis_figures.cpp, docs/analysis.md):
// analyze() draws a study's figures from its summary and rows through
// study_figures; the builders a test inspects are declared here too.
// A namespace of its own rather than a second `detail` inside
// texel::experiment (it would hide texel::detail from unqualified lookups).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "studies.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/plot.hpp"

namespace texel::experiment::analysis_figures {

/// Figures of one study from its summary (as analyze() builds it) and its
/// non-practice rows; writes into options.out_dir and returns the paths.
std::vector<std::string> study_figures(const Study& study, const nlohmann::ordered_json& summary,
                                       const std::vector<const TrialRow*>& rows, const AnalysisOptions& options);

/// Staircase tracks: one panel per participant (and session), one line per
/// block of the intensities presented — one point per answered trial, never
/// the value computed after the last answer — reversals marked; a run that
/// stopped before its stopping rule is labelled "not finished".
Figure staircase_tracks(const Study& study, const std::vector<const TrialRow*>& rows);

}  // namespace texel::experiment::analysis_figures
