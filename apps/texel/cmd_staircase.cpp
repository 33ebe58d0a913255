// texel staircase: replays an N-up/M-down staircase (PsychoPy StairHandler
// semantics, docs/procedures.md) over a list of answers and prints the track:
// intensities, reversals, finished, next value. The same library object the
// experiment engine steps; this command only parses and formats.
//
// Answers after the staircase finished are an error (exit 2), not ignored:
// a longer answer list than the procedure accepts means the protocol and the
// data disagree, and silently dropping answers would hide that.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "texel/error.hpp"
#include "texel/experiment/staircase.hpp"

namespace texel::cli {

namespace {

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  for (char ch : text) {
    if (ch == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (ch != ' ') {
      cur += ch;
    }
  }
  out.push_back(cur);
  return out;
}

std::vector<double> parse_steps(const std::string& text) {
  std::vector<double> steps;
  for (const std::string& t : split_commas(text)) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (t.empty() || used != t.size())
      throw InvalidArgument("--steps: '" + text + "' has '" + t + "' (allowed: comma-separated numbers > 0, e.g. 0.1,0.01)");
    steps.push_back(v);
  }
  return steps;
}

std::vector<bool> parse_responses(const std::string& text) {
  std::vector<bool> answers;
  if (text.empty()) return answers;
  for (const std::string& t : split_commas(text)) {
    if (t == "1")
      answers.push_back(true);
    else if (t == "0")
      answers.push_back(false);
    else
      throw InvalidArgument("--responses: '" + t + "' at position " + std::to_string(answers.size() + 1) +
                            " (allowed: 1 for correct, 0 for wrong, comma-separated)");
  }
  return answers;
}

// Library field names → the flags the user typed.
std::string flag_message(std::string msg) {
  static const std::pair<const char*, const char*> names[] = {
      {"start_value", "--start"},       {"step_sizes", "--steps"},  {"n_up", "--n-up"},     {"n_down", "--n-down"},
      {"n_reversals", "--n-reversals"}, {"n_trials", "--n-trials"}, {"min_value", "--min"}, {"max_value", "--max"},
      {"step_type", "--step-type"},     {"answers", "--responses"}};
  for (const auto& [field, flag] : names) {
    for (std::size_t pos = msg.find(field); pos != std::string::npos; pos = msg.find(field, pos)) {
      msg.replace(pos, std::string(field).size(), flag);
      pos += std::string(flag).size();
    }
  }
  return msg;
}

}  // namespace

void register_staircase(CLI::App& app) {
  struct Args {
    double start = 0;
    std::string steps;
    int n_up = 1;
    int n_down = 3;
    std::optional<int> n_reversals;
    int n_trials = 0;
    std::string step_type = "lin";
    std::optional<double> min_value, max_value;
    bool no_initial_rule = false;
    std::string end_value = "next";
    std::string responses;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("staircase", "Replay an N-up/M-down staircase over answers (PsychoPy StairHandler semantics)");
  cmd->add_option("--start", a->start, "Start value (never clamped)")->required();
  cmd->add_option("--steps", a->steps, "Step sizes, comma-separated (e.g. 0.1,0.01,0.001)")->required();
  cmd->add_option("--n-up", a->n_up, "Wrong answers in a row that move the value up (default 1)");
  cmd->add_option("--n-down", a->n_down, "Correct answers in a row that move the value down (default 3)");
  cmd->add_option("--n-reversals", a->n_reversals, "Reversals to finish (default and minimum: number of steps)");
  cmd->add_option("--n-trials", a->n_trials, "Minimum number of trials (default 0)");
  cmd->add_option("--step-type", a->step_type, "lin | log | db (default lin)");
  cmd->add_option("--min", a->min_value, "Lowest value after a move down");
  cmd->add_option("--max", a->max_value, "Highest value after a move up");
  cmd->add_flag("--no-initial-rule", a->no_initial_rule, "No 1-up/1-down rule before the first reversal");
  cmd->add_option("--end-value", a->end_value,
                  "The staircase's result: next (computed after the last answer) | last-presented (default next)");
  cmd->add_option("--responses", a->responses, "Answers, comma-separated: 1 correct, 0 wrong")->required();
  cmd->add_flag("--json", a->json, "Print JSON");
  cmd->callback([a] {
    experiment::StaircaseConfig c;
    c.start_value = a->start;
    c.step_sizes = parse_steps(a->steps);
    c.n_up = a->n_up;
    c.n_down = a->n_down;
    c.n_reversals = a->n_reversals;
    c.n_trials = a->n_trials;
    c.step_type = experiment::parse_step_type(a->step_type, "--step-type");
    c.min_value = a->min_value;
    c.max_value = a->max_value;
    c.apply_initial_rule = !a->no_initial_rule;
    c.end_value = experiment::parse_end_value(a->end_value, "--end-value");
    const std::vector<bool> answers = parse_responses(a->responses);
    std::optional<experiment::Staircase> s;
    try {
      s.emplace(experiment::Staircase::replay(c, answers));
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(flag_message(e.what()));
    }
    if (a->json) {
      nlohmann::ordered_json j;
      j["trials"] = s->trials();
      j["intensities"] = s->intensities();
      nlohmann::ordered_json r = nlohmann::ordered_json::array();
      for (bool b : s->responses()) r.push_back(b ? 1 : 0);
      j["responses"] = r;
      j["reversal_trials"] = s->reversal_trials();
      j["reversal_intensities"] = s->reversal_intensities();
      j["n_reversals"] = s->n_reversals();
      j["finished"] = s->finished();
      j["next_value"] = s->computed_value();
      j["end_value"] = std::string(experiment::to_string(c.end_value));
      j["convergent_value"] = s->convergent_value();
      j["current_step"] = s->current_step();
      if (!s->reversal_intensities().empty()) {
        const std::size_t n = s->reversal_intensities().size();
        j["mean_last_reversals"] = s->mean_last_reversals(std::min<std::size_t>(n, 6));
        j["mean_last_reversals_k"] = std::min<std::size_t>(n, 6);
      }
      print_json(j);
      return;
    }
    std::printf("%5s  %12s  %6s  %s\n", "trial", "intensity", "answer", "reversal");
    std::size_t next_rev = 0;
    const auto& rt = s->reversal_trials();
    for (std::size_t i = 0; i < s->trials(); ++i) {
      const bool rev = next_rev < rt.size() && rt[next_rev] == i;
      if (rev) ++next_rev;
      std::printf("%5zu  %12.6g  %6d  %s\n", i, s->intensities()[i], s->responses()[i] ? 1 : 0, rev ? "yes" : "");
    }
    std::printf("reversals: %zu of %d (trials", rt.size(), s->n_reversals());
    for (std::size_t t : rt) std::printf(" %zu", t);
    std::printf(")\nfinished: %s\nnext value: %.6g\nconvergent value (end value %s): %.6g\n", s->finished() ? "yes" : "no",
                s->computed_value(), std::string(experiment::to_string(c.end_value)).c_str(), s->convergent_value());
  });
}

}  // namespace texel::cli
