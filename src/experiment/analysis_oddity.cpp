// The 2-D oddity studies' analysis (docs/analysis.md "2-D studies"):
// proportion correct against chance, direction effects.
#include "analysis_common.hpp"

#include <map>
#include <set>

#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/hypergeometric.hpp>
#include <boost/math/distributions/normal.hpp>

namespace texel::experiment::analysis_common {

std::pair<double, double> wilson(double k, double n, double level) {
  const double z = boost::math::quantile(boost::math::normal_distribution<>(), 0.5 + level / 2);
  const double p = k / n, z2 = z * z / n;
  const double centre = (p + z2 / 2) / (1 + z2), half = z * std::sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z2);
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

double binomial_above(double k, double n, double p0) {
  if (k <= 0) return 1.0;
  return boost::math::cdf(boost::math::complement(boost::math::binomial_distribution<>(n, p0), k - 1));
}

namespace {

// --------------------------------------------------------- 2-D oddity studies

// Fisher's exact test, one-sided: is the proportion correct of (k1 of n1)
// lower than that of (k0 of n0)? P(X <= k1), X hypergeometric given the margins.
double fisher_lower(unsigned k1, unsigned n1, unsigned k0, unsigned n0) {
  const boost::math::hypergeometric_distribution<> h(k1 + k0, n1, n1 + n0);
  return std::min(1.0, boost::math::cdf(h, k1));
}

}  // namespace

json oddity_summary(const Study& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  struct Cell {
    std::string block, mode;
    double direction = missing;
    unsigned n = 0, k = 0;
    std::set<std::string> participants;
    // Strokes on a 2-D display (rows with direction_compliant).
    unsigned stroked = 0, compliant = 0, compliant_correct = 0;
    std::vector<double> deviations;
  };
  Ordered names;
  std::vector<Cell> cells;
  for (const TrialRow* r : rows) {
    if (r->task != "oddity-2d" || !std::isfinite(r->correct)) continue;
    const std::size_t i = names.add(r->condition);
    if (i == cells.size()) {
      Cell c;
      c.block = r->block;
      c.mode = r->reference;
      c.direction = r->intensity;
      cells.push_back(std::move(c));
    }
    cells[i].n += 1;
    cells[i].k += r->correct > 0.5 ? 1 : 0;
    cells[i].participants.insert(r->participant);
    if (std::isfinite(r->direction_compliant)) {
      cells[i].stroked += 1;
      const bool ok = r->direction_compliant > 0.5;
      cells[i].compliant += ok ? 1 : 0;
      cells[i].compliant_correct += ok && r->correct > 0.5 ? 1 : 0;
      if (std::isfinite(r->stroke_deviation_deg)) cells[i].deviations.push_back(r->stroke_deviation_deg);
    }
  }
  // In a fixed order: by block (as first met), mode, direction difference, name.
  Ordered blocks;
  for (const Cell& c : cells) blocks.add(c.block);
  std::vector<std::size_t> order(cells.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const Cell &x = cells[a], &y = cells[b];
    return std::make_tuple(blocks.add(x.block), x.mode, x.direction, names.names[a]) <
           std::make_tuple(blocks.add(y.block), y.mode, y.direction, names.names[b]);
  });
  {
    std::vector<Cell> sorted;
    Ordered sorted_names;
    for (std::size_t i : order) sorted.push_back(cells[i]), sorted_names.names.push_back(names.names[i]);
    cells = std::move(sorted);
    names = std::move(sorted_names);
  }
  constexpr double chance = 1.0 / 3.0;
  json out = json::object();
  out["chance"] = chance;
  json cj = json::array();
  text += std::string(study.title) + " (oddity, chance 1/3; " + fmt(o.level * 100, 0) + " % Wilson CIs)\n";
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const Cell& c = cells[i];
    const auto [lo, hi] = wilson(c.k, c.n, o.level);
    const double p_chance = binomial_above(c.k, c.n, chance);
    cj.push_back(json{{"condition", names.names[i]},
                      {"block", c.block},
                      {"mode", c.mode},
                      {"direction_difference_deg", num(c.direction)},
                      {"participants", c.participants.size()},
                      {"trials", c.n},
                      {"correct", c.k},
                      {"proportion", num(static_cast<double>(c.k) / c.n)},
                      {"ci_low", lo},
                      {"ci_high", hi},
                      {"p_above_chance", p_chance},
                      {"above_chance", p_chance < 1 - o.level}});
    text += "  " + names.names[i] + ": " + std::to_string(c.k) + "/" + std::to_string(c.n) +
            " correct = " + fmt(static_cast<double>(c.k) / c.n) + " [" + fmt(lo) + ", " + fmt(hi) +
            "], above chance: " + fmt_p(p_chance) + "\n";
    if (c.stroked > 0) {
      // Direction compliance on a 2-D display (docs/experiments.md "The 2-D
      // display presenter"): trials whose every interval was stroked along
      // its line, the largest deviation per trial, and the proportion
      // correct among the compliant trials.
      const double median = c.deviations.empty() ? missing : stats::quantile(c.deviations, 0.5);
      cj.back()["direction_compliance"] =
          json{{"trials_stroked", c.stroked},
               {"compliant", c.compliant},
               {"proportion", num(static_cast<double>(c.compliant) / c.stroked)},
               {"deviation_deg_median", num(median)},
               {"deviation_deg_max",
                num(c.deviations.empty() ? missing : *std::max_element(c.deviations.begin(), c.deviations.end()))},
               {"correct_when_compliant", c.compliant_correct},
               {"proportion_correct_when_compliant",
                num(c.compliant ? static_cast<double>(c.compliant_correct) / c.compliant : missing)}};
      text +=
          "    strokes: " + std::to_string(c.compliant) + "/" + std::to_string(c.stroked) + " trials along the asked directions" +
          (c.deviations.empty() ? std::string(", no interval stroked") : ", median largest deviation " + fmt(median, 1) + "°") +
          (c.compliant ? ", correct when compliant " + std::to_string(c.compliant_correct) + "/" + std::to_string(c.compliant)
                       : std::string()) +
          "\n";
    }
  }
  out["conditions"] = std::move(cj);
  if (study.direction_effects) {
    // A direction pair is discriminated when the odd texture is found less
    // often than with both swipes along one direction (the mode's baseline,
    // direction difference 0 in the same block): the pair's two members then
    // differ too, and the participant picks one of them.
    json ej = json::array();
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const Cell& c = cells[i];
      if (!(c.direction > 0)) continue;
      for (std::size_t j = 0; j < cells.size(); ++j) {
        const Cell& b = cells[j];
        if (b.block != c.block || b.mode != c.mode || b.direction != 0.0) continue;
        const double p = fisher_lower(c.k, c.n, b.k, b.n);
        const double drop = static_cast<double>(b.k) / b.n - static_cast<double>(c.k) / c.n;
        ej.push_back(json{{"condition", names.names[i]},
                          {"baseline", names.names[j]},
                          {"mode", c.mode},
                          {"direction_difference_deg", c.direction},
                          {"drop", drop},
                          {"p_fisher", p},
                          {"directions_discriminated", p < 1 - o.level}});
        text += "  " + names.names[i] + " vs " + names.names[j] + ": drop " + fmt(drop) + ", Fisher exact (one-sided) " +
                fmt_p(p) + (p < 1 - o.level ? ": directions discriminated\n" : ": not discriminated\n");
        break;
      }
    }
    out["direction_effects"] = std::move(ej);
  }
  return out;
}

}  // namespace texel::experiment::analysis_common
