// texel stats: the group statistics of the studies on a long-format CSV
// (one row per trial, e.g. `texel experiment export`, or any R / pandas
// table): repeated-measures ANOVA, one-sample and paired t-tests, and the
// 95 % confidence ellipse of a bivariate mean. Thin: read the table, call
// texel::experiment::stats, format (docs/statistics.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "texel/error.hpp"
#include "texel/experiment/stats.hpp"
#include "texel/experiment/table.hpp"

namespace texel::cli {
namespace {

namespace st = texel::experiment::stats;

std::string fmt(double v, int digits = 6) {
  if (std::isnan(v)) return "NA";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// Prints rows as a column-aligned table (first column left, the rest right).
void print_table(const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> w;
  for (const auto& r : rows)
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (w.size() <= i) w.push_back(0);
      w[i] = std::max(w[i], r[i].size());
    }
  for (const auto& r : rows) {
    std::string line;
    for (std::size_t i = 0; i < r.size(); ++i) {
      const std::string pad(w[i] - r[i].size(), ' ');
      line += i == 0 ? r[i] + pad : "  " + pad + r[i];
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    std::cout << line << "\n";
  }
}

void check_level(double level) {
  if (!(level > 0.0 && level < 1.0)) throw InvalidArgument("--level " + fmt(level) + " is outside the allowed range (0, 1)");
}

// Library messages start "function: field ..." with the library's parameter
// names; the user typed flags and column names. Strip the function name,
// rename the leading field (e.g. "x" -> "column 'rt' (--column)") and keep the
// rest, which already carries the value and what is allowed.
template <class F>
auto translated(const std::string& function, const std::vector<std::pair<std::string, std::string>>& fields,
                const std::string& suffix, F&& f) {
  try {
    return f();
  } catch (const InvalidArgument& e) {
    std::string m = e.what();
    if (m.rfind(function + ": ", 0) == 0) m.erase(0, function.size() + 2);
    for (const auto& [from, to] : fields)
      if (m.rfind(from + " ", 0) == 0) {
        m = to + m.substr(from.size());
        break;
      }
    throw InvalidArgument(m + suffix);
  }
}

std::string col(const std::string& name, const std::string& flag) { return "column '" + name + "' (" + flag + ")"; }

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> r;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) r.push_back(item);
  if (!s.empty() && s.back() == ',') r.emplace_back();
  return r;
}

void register_anova(CLI::App& stats) {
  struct Args {
    std::string csv, subject, within, dv;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = stats.add_subcommand("anova", "Repeated-measures ANOVA (one or two within factors, Greenhouse-Geisser)");
  cmd->add_option("csv", a->csv, "Long-format CSV (one row per observation)")->required();
  cmd->add_option("--subject", a->subject, "Column naming the subject (participant)")->required();
  cmd->add_option("--within", a->within, "Within-subject factor column(s): A or A,B")->required();
  cmd->add_option("--dv", a->dv, "Column of the dependent variable (numbers; empty/NA = missing)")->required();
  cmd->add_flag("--json", a->json, "Print the ANOVA table as JSON");
  cmd->callback([a] {
    const std::vector<std::string> factors = split_commas(a->within);
    if (factors.empty() || factors.size() > 2)
      throw InvalidArgument("--within '" + a->within + "' names " + std::to_string(factors.size()) +
                            " factor(s); give one or two columns separated by a comma");
    for (const auto& f : factors)
      if (f.empty()) throw InvalidArgument("--within '" + a->within + "' has an empty column name");
    const experiment::Table t = experiment::load_csv_table(a->csv);
    const std::size_t cs = t.column(a->subject);
    std::vector<std::size_t> cf;
    for (const auto& f : factors) cf.push_back(t.column(f));
    const std::vector<double> dv = t.numbers(a->dv);
    std::vector<st::Observation> obs;
    obs.reserve(t.rows());
    for (std::size_t r = 0; r < t.rows(); ++r) {
      st::Observation o;
      o.subject = t.cells[r][cs];
      for (std::size_t c : cf) o.levels.push_back(t.cells[r][c]);
      o.value = dv[r];
      obs.push_back(std::move(o));
    }
    const st::AnovaTable res = translated("rm_anova", {{"subject", col(a->subject, "--subject")}}, " [--dv " + a->dv + "]",
                                          [&] { return st::rm_anova(obs, factors); });
    if (a->json) {
      nlohmann::ordered_json j;
      j["test"] = "rm_anova";
      j["csv"] = a->csv;
      j["dv"] = a->dv;
      j["subject"] = a->subject;
      j.update(nlohmann::ordered_json::parse(st::to_json(res)));
      print_json(j);
      return;
    }
    std::cout << "Repeated-measures ANOVA of " << a->dv << " (" << res.subjects << " subjects, within: " << a->within << ")\n";
    std::vector<std::vector<std::string>> rows{{"effect", "df", "df_err", "SS", "SS_err", "F", "p", "eta2_p", "GG_eps", "p_GG"}};
    for (const auto& e : res.effects)
      rows.push_back({e.effect, fmt(e.df), fmt(e.df_error), fmt(e.ss), fmt(e.ss_error), fmt(e.f, 5), fmt(e.p, 4),
                      fmt(e.partial_eta2, 4), e.sphericity_applies ? fmt(e.gg_epsilon, 4) : "-",
                      e.sphericity_applies ? fmt(e.p_gg, 4) : "-"});
    print_table(rows);
  });
}

void register_ttest(CLI::App& stats) {
  struct Args {
    std::string csv, column;
    std::optional<std::string> paired;
    double mu = 0.0, level = 0.95;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = stats.add_subcommand("ttest", "One-sample t-test of a column, or paired t-test of COL - COL2");
  cmd->add_option("csv", a->csv, "CSV with a header row")->required();
  cmd->add_option("--column", a->column, "Column tested (numbers; empty/NA = missing)")->required();
  auto* mu = cmd->add_option("--mu", a->mu, "Hypothesised mean (one-sample; default 0)");
  cmd->add_option("--paired", a->paired, "Second column: paired test of COL - COL2 (rows with a missing side dropped)")
      ->excludes(mu);
  cmd->add_option("--level", a->level, "Confidence level of the interval, in (0, 1) (default 0.95)");
  cmd->add_flag("--json", a->json, "Print the result as JSON");
  cmd->callback([a] {
    check_level(a->level);
    if (!std::isfinite(a->mu)) throw InvalidArgument("--mu " + fmt(a->mu) + " must be a finite number");
    const experiment::Table t = experiment::load_csv_table(a->csv);
    const std::vector<double> x = t.numbers(a->column);
    st::TTest r;
    std::string label;
    if (a->paired) {
      const std::vector<double> y = t.numbers(*a->paired);
      label = a->column + " - " + *a->paired;
      r = translated("t_test_paired", {{"a - b", col(a->column, "--column") + " - " + col(*a->paired, "--paired")}}, "",
                     [&] { return st::t_test_paired(x, y, a->level); });
    } else {
      label = a->column;
      r = translated("t_test_one_sample", {{"x", col(a->column, "--column")}}, "",
                     [&] { return st::t_test_one_sample(x, a->mu, a->level); });
    }
    if (a->json) {
      nlohmann::ordered_json j;
      j["test"] = a->paired ? "paired_t" : "one_sample_t";
      j["csv"] = a->csv;
      j["column"] = a->column;
      if (a->paired) j["paired"] = *a->paired;
      j.update(nlohmann::ordered_json::parse(st::to_json(r)));
      print_json(j);
      return;
    }
    std::cout << (a->paired ? "Paired t-test of " : "One-sample t-test of ") << label << " against mu = " << fmt(r.mu) << "\n";
    print_table({{"n", "mean", "sd", "se", "t", "df", "p", fmt(100 * r.level, 4) + "% CI", "cohen_d"},
                 {std::to_string(r.n), fmt(r.mean), fmt(r.sd), fmt(r.se), fmt(r.t, 5), fmt(r.df), fmt(r.p, 4),
                  "[" + fmt(r.ci_low) + ", " + fmt(r.ci_high) + "]", fmt(r.cohen_d, 4)}});
  });
}

void register_ellipse(CLI::App& stats) {
  struct Args {
    std::string csv, x, y;
    std::optional<std::string> by;
    double level = 0.95;
    std::size_t outline = 0;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = stats.add_subcommand("ellipse", "Confidence ellipse of a bivariate mean (Hotelling's T^2)");
  cmd->add_option("csv", a->csv, "CSV with a header row")->required();
  cmd->add_option("--x", a->x, "Column of x (e.g. matched pitch, dB)")->required();
  cmd->add_option("--y", a->y, "Column of y (e.g. matched irregularity, dB)")->required();
  cmd->add_option("--by", a->by, "Group column: one ellipse per value, in order of first appearance");
  cmd->add_option("--level", a->level, "Confidence level, in (0, 1) (default 0.95)");
  cmd->add_option("--outline", a->outline, "With --json: also list this many boundary points per ellipse (0-100000)")
      ->check(CLI::Range(0, 100000));
  cmd->add_flag("--json", a->json, "Print the ellipses as JSON");
  cmd->callback([a] {
    check_level(a->level);
    const experiment::Table t = experiment::load_csv_table(a->csv);
    const std::vector<double> xs = t.numbers(a->x), ys = t.numbers(a->y);
    std::vector<std::string> groups;
    std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> data;
    const std::vector<std::string> by = a->by ? t.strings(*a->by) : std::vector<std::string>(t.rows());
    for (std::size_t r = 0; r < t.rows(); ++r) {
      auto [it, fresh] = data.try_emplace(by[r]);
      if (fresh) groups.push_back(by[r]);
      it->second.first.push_back(xs[r]);
      it->second.second.push_back(ys[r]);
    }
    if (groups.empty()) throw InvalidArgument("'" + a->csv + "' has no data rows; an ellipse needs at least 3");
    std::vector<st::Ellipse> res;
    for (const auto& g : groups) {
      const std::string where = a->by ? " [group " + *a->by + " = '" + g + "']" : "";
      res.push_back(translated("mean_confidence_ellipse", {{"x, y", col(a->x, "--x") + ", " + col(a->y, "--y")}}, where,
                               [&] { return st::mean_confidence_ellipse(data[g].first, data[g].second, a->level); }));
    }
    if (a->json) {
      nlohmann::ordered_json j;
      j["test"] = "mean_confidence_ellipse";
      j["csv"] = a->csv;
      j["x"] = a->x;
      j["y"] = a->y;
      if (a->by) j["by"] = *a->by;
      j["level"] = a->level;
      j["ellipses"] = nlohmann::ordered_json::array();
      for (std::size_t i = 0; i < res.size(); ++i) {
        const st::Ellipse& e = res[i];
        nlohmann::ordered_json x;
        if (a->by) x["group"] = groups[i];
        x.update(nlohmann::ordered_json::parse(st::to_json(e)));
        if (a->outline > 0) {
          nlohmann::ordered_json pts = nlohmann::ordered_json::array();
          for (const auto& p : e.outline(a->outline)) pts.push_back({p[0], p[1]});
          x["outline"] = std::move(pts);
        }
        j["ellipses"].push_back(std::move(x));
      }
      print_json(j);
      return;
    }
    std::cout << fmt(100 * a->level, 4) << "% confidence ellipse of the mean of (" << a->x << ", " << a->y << ")\n";
    std::vector<std::vector<std::string>> rows{{a->by ? *a->by : "group", "n", "mean_x", "mean_y", "cov_xx", "cov_xy", "cov_yy",
                                                "semi_major", "semi_minor", "angle_deg"}};
    for (std::size_t i = 0; i < res.size(); ++i) {
      const st::Ellipse& e = res[i];
      rows.push_back({a->by ? groups[i] : "all", std::to_string(e.n), fmt(e.mean_x), fmt(e.mean_y), fmt(e.cov_xx), fmt(e.cov_xy),
                      fmt(e.cov_yy), fmt(e.semi_major), fmt(e.semi_minor), fmt(e.angle_deg, 5)});
    }
    print_table(rows);
  });
}

}  // namespace

void register_stats(CLI::App& app) {
  auto* cmd = app.add_subcommand("stats", "Group statistics on a long-format CSV: anova, ttest, ellipse");
  cmd->require_subcommand(1);
  register_anova(*cmd);
  register_ttest(*cmd);
  register_ellipse(*cmd);
}

}  // namespace texel::cli
