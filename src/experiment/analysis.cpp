// Per-study summaries of the trial rows (analysis.hpp): what the thesis
// reports for each study, computed from the long-format rows alone so the
// same numbers come out of the session store and of an exported CSV.
//
// Unit of analysis: the participant. Repeated rows of one participant (two
// sessions, two matches of one reference) are averaged before a group
// statistic, so no test treats trials of one person as independent people
// (docs/analysis.md, "Unit of analysis" [choice]). Tests that cannot run
// (too few participants, no variance, an incomplete design) are reported as
// {"skipped": reason} from the stats layer's own message.
//
// This file holds analyze() itself: the options' checks, the dispatch by
// study design (studies.hpp), the runs tables; each study's summary is in
// its own file (analysis_common.hpp lists them).
#include "texel/experiment/analysis.hpp"

#include <filesystem>
#include <map>
#include <set>

#include <unistd.h>

#include "analysis_common.hpp"
#include "analysis_figures.hpp"
#include "texel/io.hpp"

namespace texel::experiment {

using namespace analysis_common;

std::string_view to_string(FigureFormat f) { return choice_name(figure_formats, static_cast<int>(f)); }
std::string_view to_string(ConvergentValue c) { return choice_name(convergent_values, static_cast<int>(c)); }
std::string_view to_string(MemoryRule r) { return choice_name(memory_rules, static_cast<int>(r)); }
std::string_view to_string(ConfidenceDistance d) { return choice_name(confidence_distances, static_cast<int>(d)); }

namespace {

// The rules visit_options states, applied from that description, for a C++
// caller that fills the struct directly; and the one rule between two options.
void check_options(const AnalysisOptions& o) {
  visit_options(o, [](const auto& v, const OptionSpec& spec) {
    using T = std::remove_cvref_t<decltype(v)>;
    const std::string name = "analysis " + std::string(spec.key);
    if constexpr (std::is_enum_v<T>) {
      if (choice_name(spec.choices, static_cast<int>(v)).empty())
        throw InvalidArgument(name + " is " + std::to_string(static_cast<int>(v)) + ", not one of its values");
    } else if constexpr (!std::is_same_v<T, bool>) {
      check_option_value(spec, static_cast<double>(v), name);
    }
  });
  if (!(o.memory_errors_sd_tolerance < o.memory_errors_sd))
    throw InvalidArgument("analysis memory_errors_sd_tolerance is " + texel::detail::num(o.memory_errors_sd_tolerance) +
                          "; allowed below memory_errors_sd (" + texel::detail::num(o.memory_errors_sd) + ")");
}

/// A CSV field: quoted when it holds a separator, a quote or a line break.
std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string q = "\"";
  for (const char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_number(const json& j) { return j.is_number() ? texel::detail::num(j.get<double>()) : std::string(); }

/// The staircase runs as CSV (one row per participant × session × block):
/// what the summary's `runs` hold, with `status` "finished" / "not
/// finished" and `convergent` empty for a run that is not finished.
std::string runs_csv(const json& summary) {
  std::string out =
      "participant,session_id,block,group,fine_strength,trials,reversals,status,in_group_statistics,end_value,convergent,"
      "threshold_last_k,threshold_reversals_used\n";
  for (const auto& r : summary["runs"]) {
    out += csv_field(r["participant"].get<std::string>()) + "," + std::to_string(r["session_id"].get<std::int64_t>()) + "," +
           csv_field(r["block"].get<std::string>()) + "," +
           (r.contains("group") ? csv_field(r["group"].get<std::string>()) : std::string()) + "," +
           (r.contains("fine_strength") ? csv_number(r["fine_strength"]) : std::string()) + "," +
           std::to_string(r["trials"].get<std::size_t>()) + "," + std::to_string(r["reversals"].get<std::size_t>()) + "," +
           r["status"].get<std::string>() + "," + (r["in_group_statistics"].get<bool>() ? "1" : "0") + "," +
           csv_number(r["end_value"]) + "," + csv_number(r["convergent"]) + "," + csv_number(r["threshold_last_k"]) + "," +
           std::to_string(r["threshold_reversals_used"].get<std::size_t>()) + "\n";
  }
  return out;
}

}  // namespace

double memory_errors_limit(double mean, double sd, const AnalysisOptions& o) {
  return mean + (o.memory_errors_sd - o.memory_errors_sd_tolerance) * sd;
}

namespace {

AnalysisReport analyze_into(const std::vector<TrialRow>& rows, const AnalysisOptions& options) {
  std::map<std::string, Rows> by_study;
  for (const TrialRow& r : rows)
    if (!r.practice) by_study[r.study].push_back(&r);
  AnalysisReport report;
  json summary = json::object();
  for (const Study& st : studies()) {  // the summary's key order
    const std::string study(st.name);
    auto it = by_study.find(study);
    if (it == by_study.end()) continue;
    Rows& rs = it->second;
    // Trial order within each participant's session, whatever the input order.
    std::stable_sort(rs.begin(), rs.end(), [](const TrialRow* a, const TrialRow* b) {
      return std::tie(a->participant, a->session_id, a->trial) < std::tie(b->participant, b->session_id, b->trial);
    });
    std::set<std::string> participants;
    for (const TrialRow* r : rs) participants.insert(r->participant);
    json s;
    switch (st.design) {
      case StudyDesign::staircase: s = staircase_summary(study, rs, options, report.text); break;
      case StudyDesign::matching: s = match_study(study, rs, options, report.text); break;
      case StudyDesign::quantization: s = quantization_summary(rs, options, report.text); break;
      case StudyDesign::guided: s = guided_summary(rs, options, report.text); break;
      case StudyDesign::memory: s = memory_summary(study, rs, options, report.text); break;
      case StudyDesign::oddity: s = oddity_summary(st, rs, options, report.text); break;
      case StudyDesign::playback: s = playback_summary(st, rs, options, report.text); break;
    }
    json head{{"participants", participants.size()}, {"rows", rs.size()}};
    // Reaction times: each participant's median (robust to a trial left
    // open), described over participants.
    std::map<std::string, std::vector<double>> rts;
    for (const TrialRow* r : rs)
      if (std::isfinite(r->rt_ms)) rts[r->participant].push_back(r->rt_ms);
    if (!rts.empty()) {
      std::vector<double> medians;
      for (const auto& [p, v] : rts) medians.push_back(stats::quantile(v, 0.5));
      head["rt_ms_median"] = describe_json(medians);
    }
    head.update(s);
    if (st.design == StudyDesign::guided && summary.contains("free-exploration") && head.contains("matches"))
      head["spread_vs_free_exploration"] = spread_comparison(summary["free-exploration"], head, options, report.text);
    summary[study] = std::move(head);
    if (!options.out_dir.empty()) {
      for (auto& f : analysis_figures::study_figures(st, summary[study], rs, options)) report.figures.push_back(std::move(f));
      if (st.design == StudyDesign::staircase) {
        const std::string path = (std::filesystem::path(options.out_dir) / (study + "-runs.csv")).string();
        write_file_atomic(path, runs_csv(summary[study]));
        report.tables.push_back(path);
      }
    }
  }
  report.summary = summary.dump();
  return report;
}

}  // namespace

// Figures and tables are drawn into a hidden folder inside out_dir and moved
// into out_dir only when every study has been summarised and drawn: a failure
// (a library that cannot be opened, a full disk) leaves no figure of this run,
// and no out_dir it created.
AnalysisReport analyze(const std::vector<TrialRow>& rows, const AnalysisOptions& options) {
  check_options(options);
  if (options.out_dir.empty()) return analyze_into(rows, options);
  namespace fs = std::filesystem;
  const fs::path out(options.out_dir);
  std::error_code ec;
  const bool existed = fs::exists(out, ec);
  fs::create_directories(out, ec);
  if (ec) throw IoError("cannot create figure directory '" + options.out_dir + "': " + ec.message());
  const fs::path staging = out / (".texel-analysis-" + std::to_string(::getpid()));
  fs::remove_all(staging, ec);
  fs::create_directory(staging, ec);
  if (ec) throw IoError("cannot write into figure directory '" + options.out_dir + "': " + ec.message());
  const auto discard = [&] {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    if (!existed) fs::remove(out, ignored);  // only if empty
  };
  AnalysisReport report;
  try {
    AnalysisOptions staged = options;
    staged.out_dir = staging.string();
    report = analyze_into(rows, staged);
    for (auto* paths : {&report.figures, &report.tables})
      for (std::string& p : *paths) {
        const fs::path to = out / fs::path(p).filename();
        fs::rename(p, to);
        p = to.string();
      }
  } catch (const fs::filesystem_error& e) {
    discard();
    throw IoError("cannot write figures into '" + options.out_dir + "': " + e.code().message());
  } catch (...) {
    discard();
    throw;
  }
  fs::remove(staging, ec);
  return report;
}

}  // namespace texel::experiment
