// The distributed-irregularity study's analysis (docs/analysis.md
// "Distributed irregularity"): per Irregularity level, proportion correct
// against the sequential texture's shift, the point of subjective equality
// (PSE) where the dip of the oddity curve lies, with a bootstrap CI over
// participants, and the seed-only control.
#include "analysis_common.hpp"

#include <map>
#include <set>

#include <boost/math/tools/minima.hpp>

#include "texel/random.hpp"

namespace texel::experiment::analysis_common {

namespace {

constexpr double chance = 1.0 / 3.0;
constexpr double lapse = 0.02;  // [choice] fixed, as the observers' default
constexpr int bootstrap_samples = 1000;
constexpr std::uint64_t bootstrap_stream = 0x5053450000000000ULL;  // "PSE"

// The dip: p(Δ) = γ + (1 − γ − λ)·(1 − exp(−((Δ − PSE)/α)²)), chance γ = 1/3
// at the PSE, a Weibull of slope 2 on |Δ − PSE| on either side.
double dip(double shift, double pse, double alpha) {
  const double z = (shift - pse) / alpha;
  return chance + (1 - chance - lapse) * (1 - std::exp(-z * z));
}

struct Counts {
  std::vector<double> shifts;  // ascending
  std::vector<double> k, n;    // per shift
};

double log_likelihood(const Counts& c, double pse, double alpha) {
  double ll = 0;
  for (std::size_t i = 0; i < c.shifts.size(); ++i) {
    const double p = std::clamp(dip(c.shifts[i], pse, alpha), 1e-9, 1 - 1e-9);
    ll += c.k[i] * std::log(p) + (c.n[i] - c.k[i]) * std::log1p(-p);
  }
  return ll;
}

struct Fit {
  double pse = missing, alpha = missing, log_likelihood = missing;
};

// Maximum likelihood: the PSE on a 0.25 dB grid over the shifts' range
// (widened by a quarter of it), α profiled out by Brent's method on log α
// (0.1 … 100 dB), then Brent on the PSE within a grid step of the best point.
Fit fit_dip(const Counts& c) {
  Fit best;
  if (c.shifts.size() < 3) return best;
  const auto alpha_at = [&](double pse) {
    const auto r = boost::math::tools::brent_find_minima(
        [&](double log_alpha) { return -log_likelihood(c, pse, std::exp(log_alpha)); }, std::log(0.1), std::log(100.0), 30);
    return std::make_pair(std::exp(r.first), -r.second);
  };
  const double lo = c.shifts.front(), hi = c.shifts.back(), pad = (hi - lo) / 4;
  double best_ll = -std::numeric_limits<double>::infinity(), best_pse = lo;
  constexpr double step = 0.25;
  for (double pse = lo - pad; pse <= hi + pad + 1e-9; pse += step) {
    const double ll = alpha_at(pse).second;
    if (ll > best_ll) best_ll = ll, best_pse = pse;
  }
  const auto r = boost::math::tools::brent_find_minima([&](double pse) { return -alpha_at(pse).second; }, best_pse - step,
                                                       best_pse + step, 30);
  best.pse = r.first;
  const auto [alpha, ll] = alpha_at(best.pse);
  best.alpha = alpha;
  best.log_likelihood = ll;
  return best;
}

// Counts per shift from per-participant counts (a participant may appear
// several times in a bootstrap sample).
Counts pooled(const std::vector<double>& shifts, const std::vector<const std::map<double, std::pair<double, double>>*>& who) {
  Counts c;
  c.shifts = shifts;
  c.k.assign(shifts.size(), 0);
  c.n.assign(shifts.size(), 0);
  for (const auto* p : who)
    for (std::size_t i = 0; i < shifts.size(); ++i)
      if (auto it = p->find(shifts[i]); it != p->end()) c.k[i] += it->second.first, c.n[i] += it->second.second;
  // Shifts nobody answered carry no information.
  Counts out;
  for (std::size_t i = 0; i < shifts.size(); ++i)
    if (c.n[i] > 0) out.shifts.push_back(shifts[i]), out.k.push_back(c.k[i]), out.n.push_back(c.n[i]);
  return out;
}

}  // namespace

json playback_summary(const Study& study, const Rows& rows, const AnalysisOptions& o, std::string& text) {
  // level → participant → shift → (correct, trials); controls apart.
  std::map<double, std::map<std::string, std::map<double, std::pair<double, double>>>> by_level;
  std::map<double, std::pair<double, double>> controls;
  std::map<double, std::map<double, std::map<std::string, std::pair<double, double>>>> cells;  // level → shift → arrangement
  for (const TrialRow* r : rows) {
    if (r->task != "playback-oddity" || !std::isfinite(r->correct) || !std::isfinite(r->reference_irregularity_db)) continue;
    const double level = r->reference_irregularity_db, ok = r->correct > 0.5 ? 1.0 : 0.0;
    if (r->condition == "control") {
      controls[level].first += ok, controls[level].second += 1;
      continue;
    }
    if (!std::isfinite(r->intensity)) continue;
    auto& c = by_level[level][r->participant][r->intensity];
    c.first += ok, c.second += 1;
    auto& a = cells[level][r->intensity][r->condition];
    a.first += ok, a.second += 1;
  }
  json out = json::object();
  out["chance"] = chance;
  out["model"] =
      "p(shift) = 1/3 + (1 - 1/3 - 0.02)(1 - exp(-((shift - PSE)/alpha)^2)), maximum likelihood; CI: bootstrap "
      "over participants, " +
      std::to_string(bootstrap_samples) + " resamples, percentile";
  text += std::string(study.title) +
          " (playback oddity, chance 1/3): shift = the sequential texture's Irregularity minus the simultaneous one's; "
          "PSE = the shift at which they feel alike\n";
  json levels = json::array();
  std::set<double> all_levels;
  for (const auto& [level, unused] : by_level) all_levels.insert(level);
  for (const auto& [level, unused] : controls) all_levels.insert(level);
  for (double level : all_levels) {
    json lj{{"irregularity_db", level}};
    text += "  Irregularity " + fmt(level, 1) + " dB (simultaneous):\n";
    const auto& participants = by_level[level];
    std::set<double> shift_set;
    for (const auto& [p, m] : participants)
      for (const auto& [s, kn] : m) shift_set.insert(s);
    const std::vector<double> shifts(shift_set.begin(), shift_set.end());
    json sj = json::array();
    for (double s : shifts) {
      double k = 0, n = 0;
      json by_arrangement = json::object();
      for (const auto& [a, kn] : cells[level][s]) {
        k += kn.first, n += kn.second;
        by_arrangement[a] = json{{"correct", kn.first}, {"trials", kn.second}};
      }
      const auto [lo, hi] = wilson(k, n, o.level);
      sj.push_back(json{{"shift_db", s},
                        {"trials", n},
                        {"correct", k},
                        {"proportion", k / n},
                        {"ci_low", lo},
                        {"ci_high", hi},
                        {"by_arrangement", std::move(by_arrangement)}});
      text += "    shift " + fmt(s, 1) + " dB: " + fmt(k, 0) + "/" + fmt(n, 0) + " correct = " + fmt(k / n) + " [" + fmt(lo) +
              ", " + fmt(hi) + "]\n";
    }
    lj["participants"] = participants.size();
    lj["shifts"] = std::move(sj);
    std::vector<const std::map<double, std::pair<double, double>>*> everyone;
    for (const auto& [p, m] : participants) everyone.push_back(&m);
    const Counts all = pooled(shifts, everyone);
    const Fit f = fit_dip(all);
    if (!std::isfinite(f.pse)) {
      lj["pse"] = skipped("needs answers at 3 or more shifts, got " + std::to_string(all.shifts.size()));
      text += "    PSE skipped: needs answers at 3 or more shifts\n";
    } else {
      json pj{{"pse_db", f.pse}, {"alpha_db", f.alpha}, {"log_likelihood", f.log_likelihood}, {"level", o.level}};
      if (participants.size() < 2) {
        pj["ci"] = skipped("the bootstrap over participants needs 2 or more, got " + std::to_string(participants.size()));
        text += "    PSE " + fmt(f.pse) + " dB (no CI: one participant)\n";
      } else {
        // Resample participants with replacement, refit; a fixed stream per
        // level, so the same data always give the same interval.
        const CounterRng rng(bootstrap_stream ^ static_cast<std::uint64_t>(std::llround((level + 100) * 1000)), 0);
        std::vector<double> pses;
        pses.reserve(bootstrap_samples);
        std::vector<const std::map<double, std::pair<double, double>>*> sample(everyone.size());
        for (int b = 0; b < bootstrap_samples; ++b) {
          for (std::size_t i = 0; i < sample.size(); ++i)
            sample[i] = everyone[rng.below(static_cast<std::uint64_t>(b) * everyone.size() + i, everyone.size())];
          const Fit fb = fit_dip(pooled(shifts, sample));
          if (std::isfinite(fb.pse)) pses.push_back(fb.pse);
        }
        const double lo = stats::quantile(pses, (1 - o.level) / 2), hi = stats::quantile(pses, 1 - (1 - o.level) / 2);
        const bool differs = lo > 0 || hi < 0;
        pj["ci_low"] = lo;
        pj["ci_high"] = hi;
        pj["bootstrap_fits"] = pses.size();
        pj["differs_from_zero"] = differs;
        text += "    PSE " + fmt(f.pse) + " dB, " + fmt(o.level * 100, 0) + " % CI [" + fmt(lo) + ", " + fmt(hi) + "]: " +
                (differs ? "simultaneous texels are felt at another Irregularity than sequential ones"
                         : "no difference in felt Irregularity shown") +
                "\n";
      }
      lj["pse"] = std::move(pj);
    }
    std::map<std::string, std::pair<double, double>> by_arrangement;  // over the shifts
    for (const auto& [shift, arrangements] : cells[level])
      for (const auto& [a, kn] : arrangements) by_arrangement[a].first += kn.first, by_arrangement[a].second += kn.second;
    json aj = json::object();
    for (const auto& [a, kn] : by_arrangement)
      aj[a] = json{{"correct", kn.first}, {"trials", kn.second}, {"proportion", kn.first / kn.second}};
    lj["arrangements"] = std::move(aj);
    if (auto it = controls.find(level); it != controls.end()) {
      const auto [k, n] = it->second;
      const auto [lo, hi] = wilson(k, n, o.level);
      const double p = binomial_above(k, n, chance);
      lj["control"] = json{{"trials", n},
                           {"correct", k},
                           {"proportion", k / n},
                           {"ci_low", lo},
                           {"ci_high", hi},
                           {"p_above_chance", p},
                           {"above_chance", p < 1 - o.level}};
      text += "    control (seeds differ only): " + fmt(k, 0) + "/" + fmt(n, 0) + " correct = " + fmt(k / n) + " [" + fmt(lo) +
              ", " + fmt(hi) + "], above chance: " + fmt_p(p) + "\n";
    }
    levels.push_back(std::move(lj));
  }
  out["levels"] = std::move(levels);
  return out;
}

/// The dip's value at `shift` for a fitted (pse, alpha): what the figure draws.
double playback_dip(double shift, double pse, double alpha) { return dip(shift, pse, alpha); }

}  // namespace texel::experiment::analysis_common
