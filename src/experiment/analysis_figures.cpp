// The analysis figures (analysis.hpp): each mirrors a figure of the thesis
// for its study, so a researcher can set them side by side — staircase
// tracks, box plots of convergent values with 95 % CIs, matched parameters
// against the references, confidence ellipses of the mean match, similarity
// matrices, rating changes under quantization, working-memory performance.
// docs/analysis.md says which question of the source each one answers.
//
// Figures are built from the study's summary (so a figure never disagrees
// with the numbers reported next to it) plus the rows where a figure shows
// every trial (tracks). Every file is written through save_figure, i.e.
// atomically (temporary + rename). One study's figures per file
// (analysis_figures_<study>.cpp, declared in analysis_figures_common.hpp);
// this file chooses a study's figures and writes them.
#include <filesystem>
#include <string>
#include <vector>

#include "analysis_figures_common.hpp"

namespace texel::experiment::analysis_figures {
namespace {

struct Writer {
  const std::string& study;
  const AnalysisOptions& o;
  std::vector<std::string> paths;
  void save(const Figure& f, const std::string& name) {
    const std::string path =
        (std::filesystem::path(o.out_dir) / (study + "-" + name + "." + std::string(to_string(o.format)))).string();
    save_figure(f, path);
    paths.push_back(path);
  }
};

}  // namespace

std::vector<std::string> study_figures(const Study& study, const nlohmann::ordered_json& summary, const Rows& rows,
                                       const AnalysisOptions& options) {
  const std::string name(study.name), title(study.title);
  Writer w{name, options, {}};
  switch (study.design) {
    case StudyDesign::staircase:
      w.save(staircase_tracks(study, rows), "tracks");
      w.save(convergent_boxes(study, summary), "convergent");
      if (study.blocks_by_fine_strength) w.save(participant_lines(study, summary), "participants");
      if (study.directional)
        if (auto f = directional_scatter(summary)) w.save(*f, "directional");
      break;
    case StudyDesign::matching:
    case StudyDesign::guided:
      if (!summary["matches"].empty()) {
        w.save(matched_vs_reference(title, summary), "matched-vs-reference");
        w.save(matched_boxes(title, summary), "matched-boxes");
        w.save(match_ellipses(title, summary, options.level), "ellipses");
      }
      if (auto f = confidence_vs_distance(title, summary)) w.save(*f, "confidence");
      if (auto f = confidence_bins(title, summary)) w.save(*f, "confidence-bins");
      if (study.ratings_figure && summary.contains("ratings")) w.save(rating_boxes(title, rows, "0 … 10"), "ratings");
      if (auto f = irregularity_normalised_figure(summary, rows)) w.save(*f, "irregularity-normalised");
      if (auto f = comparisons_figure(summary)) w.save(*f, "comparisons");
      // Beyond the own-match pairs (the source rated 25 of the 81): the matrix.
      if (study.design == StudyDesign::matching && summary.contains("similarity") &&
          summary["similarity"]["pairs_rated"].get<std::size_t>() > summary["similarity"]["references"].size())
        w.save(similarity_heatmap(summary["similarity"], title + ": similarity of references and matches", 0.0, 10.0, "match of"),
               "similarity");
      if (study.design == StudyDesign::guided) {
        w.save(guided_convergence(rows), "convergence");
        if (summary.contains("similarity"))
          w.save(
              similarity_heatmap(summary["similarity"], "Guided exploration: similarity of references and optimized renderings",
                                 1.0, 5.0, "optimized rendering of"),
              "similarity");
      }
      break;
    case StudyDesign::quantization:
      w.save(quantization_figure(summary, rows), "rating-change");
      if (auto f = match_similarity(rows)) w.save(*f, "match-similarity");
      break;
    case StudyDesign::memory:
      w.save(memory_figure(study, summary), "performance");
      if (auto f = memory_errors_trend(study, summary)) w.save(*f, "errors-trend");
      if (auto f = memory_components(summary, options.level)) w.save(*f, "effects");
      break;
    case StudyDesign::oddity: w.save(oddity_figure(study, summary, options.level), "proportion-correct"); break;
    case StudyDesign::playback:
      if (!summary["levels"].empty()) w.save(playback_figure(study, summary, options.level), "pse");
      break;
  }
  return w.paths;
}

}  // namespace texel::experiment::analysis_figures
