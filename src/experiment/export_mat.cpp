// The trial export as MATLAB variables (export_mat.hpp).
#include "texel/experiment/export_mat.hpp"

#include <algorithm>
#include <optional>
#include <string>

#include "texel/error.hpp"
#include "texel/experiment/table.hpp"

namespace texel::experiment {

std::vector<texel::mat::Variable> trials_mat_variables(const std::vector<TrialRow>& rows) {
  static const std::vector<std::string> text = {"participant", "protocol",       "study",     "block",
                                                "task",        "condition",      "reference", "variable",
                                                "response",    "correct_answer", "shown_at",  "answered_at"};
  const Table table = parse_csv_table(trials_csv(rows), "export");
  texel::mat::Struct trials;
  for (const auto& name : table.columns) {
    const bool is_text = std::find(text.begin(), text.end(), name) != text.end();
    std::optional<std::vector<double>> numbers;
    if (!is_text) try {
        numbers = table.numbers(name);
      } catch (const texel::FormatError&) {
      }
    if (numbers)
      trials.add(name, texel::mat::Matrix::column(std::move(*numbers)));
    else
      trials.add(name, texel::mat::StringColumn{table.strings(name)});
  }
  return {{"trials", std::move(trials)}};
}

}  // namespace texel::experiment
