// The trial export as MATLAB variables (docs/format.md "MATLAB .mat"): the
// one conversion `texel experiment export -o x.mat` and the studio's
// experimenter view both write.
#pragma once

#include <vector>

#include "texel/experiment/records.hpp"
#include "texel/matfile.hpp"

namespace texel::experiment {

/// A 1×1 struct `trials` with one N×1 field per trial column, in CSV order
/// (struct2table(trials) gives a table). Values go through the one CSV
/// serializer, so the .mat and the .csv cannot disagree: text fields (and
/// any column that is not all numbers) become N×1 cell arrays of char, the
/// others doubles with NaN for missing (MATLAB's missing).
std::vector<texel::mat::Variable> trials_mat_variables(const std::vector<TrialRow>& rows);

}  // namespace texel::experiment
