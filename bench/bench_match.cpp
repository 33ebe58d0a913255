// texel_bench_match: the two matching optimizers (guided exploration, the
// Bayesian one) against the SAME simulated matcher. For N seeded simulated
// participants with hidden targets drawn uniformly inside the device box, it
// reports the Euclidean error (dB) of each optimizer's current estimate after
// every comparison 1 … 20 — median and IQR — and the time per question.
// The guided optimizer's estimate between iterations is its box centroid.
//
//   texel_bench_match [--participants N] [--noise DB] [--band DB] [--json PATH]
//
// Baseline in the same run: the error of always answering the box centre
// (the prior mean), so figures read as ratios of it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "texel/experiment/bayes_match.hpp"
#include "texel/experiment/guided.hpp"
#include "texel/experiment/observer.hpp"
#include "texel/random.hpp"

using namespace texel::experiment;

namespace {

constexpr int max_comparisons = 20;

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double error_db(const MatchPoint& e, const MatchPoint& t) {
  return std::hypot(e.pitch_db - t.pitch_db, e.irregularity_db - t.irregularity_db);
}

struct Curve {
  std::string name;
  std::vector<std::vector<double>> errors = std::vector<std::vector<double>>(max_comparisons + 1);  // [comparisons][participant]
  double seconds = 0;
  long questions = 0;
};

template <class Make>
void run(Curve& curve, const std::vector<MatcherConfig>& participants, Make make) {
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t p = 0; p < participants.size(); ++p) {
    const Matcher matcher(participants[p]);
    auto opt = make(p);
    curve.errors[0].push_back(error_db(opt->estimate(), participants[p].target));
    for (int k = 1; k <= max_comparisons; ++k) {
      if (!opt->finished()) {
        const MatchQuestion q = opt->next();
        opt->answer(matcher.choose(q, static_cast<std::uint64_t>(q.index)));
        ++curve.questions;
      }
      curve.errors[static_cast<std::size_t>(k)].push_back(error_db(opt->estimate(), participants[p].target));
    }
  }
  curve.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  int n = 200;
  double noise = 2.0, band = 1.0;
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << ": missing value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--participants")
      n = std::max(1, std::atoi(value().c_str()));
    else if (a == "--noise")
      noise = std::atof(value().c_str());
    else if (a == "--band")
      band = std::atof(value().c_str());
    else if (a == "--json")
      json_path = value();
    else {
      std::cerr << "usage: texel_bench_match [--participants N] [--noise DB] [--band DB] [--json PATH]\n";
      return 2;
    }
  }

  // Participants: targets uniform in the device box, seeded per participant.
  const GuidedConfig box;
  const texel::CounterRng targets(2024, static_cast<std::uint64_t>(texel::Stream::user) + 40);
  std::vector<MatcherConfig> participants;
  for (int p = 0; p < n; ++p) {
    MatcherConfig m;
    const auto k = static_cast<std::uint64_t>(p);
    m.target = {box.pitch_min_db + (box.pitch_max_db - box.pitch_min_db) * targets.uniform(2 * k),
                box.irregularity_min_db + (box.irregularity_max_db - box.irregularity_min_db) * targets.uniform(2 * k + 1)};
    m.noise_db = noise;
    m.unsure_band_db = band;
    m.seed = 1000 + k;
    participants.push_back(m);
  }

  Curve guided{"guided"}, bayes{"bayesian"};
  run(guided, participants, [](std::size_t p) {
    GuidedConfig c;
    c.seed = 7 + p;
    return std::make_unique<GuidedOptimizer>(c);
  });
  // The Bayesian optimizer runs with its defaults (noise 2 dB, band 1 dB):
  // it matches the simulated matcher only when --noise/--band are left alone.
  run(bayes, participants, [](std::size_t p) {
    BayesConfig c;
    c.seed = 7 + p;
    return std::make_unique<BayesOptimizer>(c);
  });

  nlohmann::ordered_json out;
  out["benchmark"] = "match";
  out["participants"] = n;
  out["matcher"] = {{"noise_db", noise}, {"unsure_band_db", band}};
  out["baseline_centre_median_db"] = quantile(guided.errors[0], 0.5);
  std::printf("matching optimizers: %d simulated participants, matcher noise %.2f dB, unsure band %.2f dB\n", n, noise, band);
  std::printf("baseline (box centre, 0 comparisons): median error %.2f dB\n\n", quantile(guided.errors[0], 0.5));
  std::printf("%11s | %-26s | %-26s\n", "", "guided", "bayesian");
  std::printf("%11s | %8s %17s | %8s %17s\n", "comparisons", "median", "IQR", "median", "IQR");
  nlohmann::ordered_json opts;
  for (const Curve* c : {&guided, &bayes}) {
    nlohmann::ordered_json o;
    nlohmann::ordered_json curve = nlohmann::ordered_json::array();
    for (int k = 1; k <= max_comparisons; ++k) {
      const auto& e = c->errors[static_cast<std::size_t>(k)];
      curve.push_back(
          {{"comparisons", k}, {"median_db", quantile(e, 0.5)}, {"q25_db", quantile(e, 0.25)}, {"q75_db", quantile(e, 0.75)}});
    }
    for (int k : {5, 10, 20}) o["median_db_at_" + std::to_string(k)] = quantile(c->errors[static_cast<std::size_t>(k)], 0.5);
    o["us_per_question"] = 1e6 * c->seconds / static_cast<double>(std::max(1L, c->questions));
    o["curve"] = curve;
    opts[c->name] = o;
  }
  for (int k = 1; k <= max_comparisons; ++k) {
    const auto& g = guided.errors[static_cast<std::size_t>(k)];
    const auto& b = bayes.errors[static_cast<std::size_t>(k)];
    std::printf("%11d | %8.2f %8.2f … %6.2f | %8.2f %8.2f … %6.2f\n", k, quantile(g, 0.5), quantile(g, 0.25), quantile(g, 0.75),
                quantile(b, 0.5), quantile(b, 0.25), quantile(b, 0.75));
  }
  const double g20 = quantile(guided.errors[20], 0.5);
  int reached = 0;
  for (int k = 1; k <= max_comparisons && !reached; ++k)
    if (quantile(bayes.errors[static_cast<std::size_t>(k)], 0.5) <= g20) reached = k;
  const double b20 = quantile(bayes.errors[20], 0.5);
  const bool goal = (reached > 0 && reached <= 10) || b20 <= g20 / 2;
  std::printf("\ntime per question: guided %.2f us, bayesian %.1f us\n", opts["guided"]["us_per_question"].get<double>(),
              opts["bayesian"]["us_per_question"].get<double>());
  std::printf("bayesian reaches guided's 20-comparison median (%.2f dB) after %d comparisons; at 20: %.2f dB (%.2f of guided)\n",
              g20, reached, b20, b20 / g20);
  std::printf("goal (<= 10 comparisons, or half the error at 20): %s\n", goal ? "met" : "NOT met");
  out["optimizers"] = opts;
  out["bayesian_reaches_guided_20_at"] = reached;
  out["goal_met"] = goal;
  if (!json_path.empty()) {
    const std::string tmp = json_path + ".tmp";
    {
      std::ofstream f(tmp);
      f << out.dump(2) << "\n";
      if (!f) {
        std::cerr << "--json: cannot write '" << json_path << "'\n";
        return 1;
      }
    }
    std::filesystem::rename(tmp, json_path);
  }
  return 0;
}
