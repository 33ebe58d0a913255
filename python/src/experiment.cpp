// Binding of the experiment layer: the step-wise procedures (staircase,
// guided and Bayesian matching optimizers; next() / answer() like PsychoPy's
// handlers, so a Python loop drives the same objects as the terminal runner
// and the studio), the simulated observers, and read-only access to session
// databases as pandas-friendly records.
#include <cmath>

#include <nlohmann/json.hpp>

#include "common.hpp"
#include "texel/error.hpp"
#include "texel/experiment/bayes_match.hpp"
#include "texel/experiment/guided.hpp"
#include "texel/experiment/observer.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/staircase.hpp"
#include "texel/experiment/store.hpp"

namespace texel::python {
namespace {

using namespace texel::experiment;

// ------------------------------------------------------------------ records
// Typed cells of a TrialRow (records.hpp). Columns are emitted in
// trial_columns() order; a column this table does not know (a newer
// library) falls back to its CSV cell text, so none is ever dropped.
struct Columns {
  std::vector<std::pair<const char*, std::string TrialRow::*>> strings{{"participant", &TrialRow::participant},
                                                                       {"protocol", &TrialRow::protocol},
                                                                       {"study", &TrialRow::study},
                                                                       {"block", &TrialRow::block},
                                                                       {"task", &TrialRow::task},
                                                                       {"condition", &TrialRow::condition},
                                                                       {"reference", &TrialRow::reference},
                                                                       {"variable", &TrialRow::variable},
                                                                       {"response", &TrialRow::response},
                                                                       {"correct_answer", &TrialRow::correct_answer},
                                                                       {"shown_at", &TrialRow::shown_at},
                                                                       {"answered_at", &TrialRow::answered_at},
                                                                       {"presentation_mode", &TrialRow::presentation_mode},
                                                                       {"finger_source", &TrialRow::finger_source},
                                                                       {"swipe_flag", &TrialRow::swipe_flag}};
  std::vector<std::pair<const char*, int TrialRow::*>> ints{
      {"block_index", &TrialRow::block_index}, {"trial", &TrialRow::trial}, {"trial_in_block", &TrialRow::trial_in_block}};
  std::vector<std::pair<const char*, bool TrialRow::*>> bools{{"practice", &TrialRow::practice},
                                                              {"reversal", &TrialRow::reversal},
                                                              {"procedure_finished", &TrialRow::procedure_finished}};
  std::vector<std::pair<const char*, double TrialRow::*>> numbers{
      {"intensity", &TrialRow::intensity},
      {"next_intensity", &TrialRow::next_intensity},
      {"correct", &TrialRow::correct},
      {"rating", &TrialRow::rating},
      {"confidence", &TrialRow::confidence},
      {"rt_ms", &TrialRow::rt_ms},
      {"slider_p", &TrialRow::slider_p},
      {"slider_i", &TrialRow::slider_i},
      {"pitch_db", &TrialRow::pitch_db},
      {"irregularity_db", &TrialRow::irregularity_db},
      {"pitch_a_db", &TrialRow::pitch_a_db},
      {"irregularity_a_db", &TrialRow::irregularity_a_db},
      {"pitch_b_db", &TrialRow::pitch_b_db},
      {"irregularity_b_db", &TrialRow::irregularity_b_db},
      {"reference_pitch_db", &TrialRow::reference_pitch_db},
      {"reference_irregularity_db", &TrialRow::reference_irregularity_db},
      {"texel_length_mm", &TrialRow::texel_length_mm},
      {"coarse_strength", &TrialRow::coarse_strength},
      {"fine_strength", &TrialRow::fine_strength},
      {"quantization_db", &TrialRow::quantization_db},
      {"digit_cell", &TrialRow::digit_cell},
      {"digit_response", &TrialRow::digit_response},
      {"digit_correct", &TrialRow::digit_correct},
      {"swipe_mean_speed_mm_s", &TrialRow::swipe_mean_speed_mm_s},
      {"swipe_sd_speed_mm_s", &TrialRow::swipe_sd_speed_mm_s},
      {"directional_proportion", &TrialRow::directional_proportion},
      {"strokes", &TrialRow::strokes},
      {"stroke_deviation_deg", &TrialRow::stroke_deviation_deg},
      {"direction_compliant", &TrialRow::direction_compliant},
      {"time_limit_s", &TrialRow::time_limit_s},
      {"over_time_limit", &TrialRow::over_time_limit},
      {"interrupted", &TrialRow::interrupted},
      {"suspended_ms", &TrialRow::suspended_ms},
      {"nback_targets", &TrialRow::nback_targets},
      {"nback_hits", &TrialRow::nback_hits},
      {"nback_false_alarms", &TrialRow::nback_false_alarms}};

  // Cell of `row` in column `name` as a Python value: str, int, bool, float
  // (NaN = missing; iteration −1 = missing).
  [[nodiscard]] py::object cell(const TrialRow& row, const std::string& name) const {
    if (name == "session_id") return py::int_(row.session_id);
    if (name == "trial_number") return py::int_(row.trial + 1);
    if (name == "iteration") return py::float_(row.iteration >= 0 ? row.iteration : std::nan(""));
    for (const auto& [n, p] : strings)
      if (name == n) return py::str(row.*p);
    for (const auto& [n, p] : ints)
      if (name == n) return py::int_(row.*p);
    for (const auto& [n, p] : bools)
      if (name == n) return py::bool_(row.*p);
    for (const auto& [n, p] : numbers)
      if (name == n) return py::float_(row.*p);
    const auto j = nlohmann::json::parse(row_json(row));
    return py::str(j.contains(name) && j[name].is_string() ? j[name].get<std::string>() : std::string());
  }
};

const Columns& columns() {
  static const Columns c;
  return c;
}

}  // namespace

py::list rows_records(const std::vector<TrialRow>& rows) {
  py::list out;
  for (const auto& r : rows) {
    py::dict d;
    for (const auto& name : trial_columns()) d[py::str(name)] = columns().cell(r, name);
    out.append(d);
  }
  return out;
}

namespace {

py::dict rows_columns(const std::vector<TrialRow>& rows) {
  py::module_ np = py::module_::import("numpy");
  py::dict out;
  for (const auto& name : trial_columns()) {
    py::list cells;
    for (const auto& r : rows) cells.append(columns().cell(r, name));
    py::object dtype = py::str("object");
    if (!rows.empty()) {
      const py::object first = cells[0];
      if (py::isinstance<py::bool_>(first))
        dtype = np.attr("bool_");
      else if (py::isinstance<py::int_>(first))
        dtype = np.attr("int64");
      else if (py::isinstance<py::float_>(first))
        dtype = np.attr("float64");
    }
    out[py::str(name)] = np.attr("array")(cells, py::arg("dtype") = dtype);
  }
  return out;
}

py::object rows_py(const std::vector<TrialRow>& rows, bool as_columns) {
  return as_columns ? py::object(rows_columns(rows)) : py::object(rows_records(rows));
}

}  // namespace

// The library's one session view (to_json: the CLI's and the studio's
// fields, trials_planned -1 when adaptive) plus the stored protocol copy.
py::dict session_dict(const SessionInfo& s) {
  auto d = py::module_::import("json").attr("loads")(to_json(s)).cast<py::dict>();
  d["protocol_json"] = s.protocol_json;
  return d;
}

namespace {

// ------------------------------------------------------------------ helpers
MatchChoice choice_of(const std::string& c) { return parse_match_choice(c, "choice"); }

std::vector<MatchChoice> choices_of(const std::vector<std::string>& cs) {
  std::vector<MatchChoice> out;
  for (const auto& c : cs) out.push_back(choice_of(c));
  return out;
}

std::vector<std::string> choice_names(const std::vector<MatchChoice>& cs) {
  std::vector<std::string> out;
  for (auto c : cs) out.emplace_back(to_string(c));
  return out;
}

StaircaseConfig staircase_config(double start_value, std::vector<double> step_sizes, int n_up, int n_down,
                                 std::optional<int> n_reversals, int n_trials, const std::string& step_type,
                                 std::optional<double> min_value, std::optional<double> max_value, bool apply_initial_rule,
                                 const std::string& end_value) {
  StaircaseConfig c;
  c.start_value = start_value;
  c.step_sizes = std::move(step_sizes);
  c.n_up = n_up;
  c.n_down = n_down;
  c.n_reversals = n_reversals;
  c.n_trials = n_trials;
  c.step_type = parse_step_type(step_type, "step_type");
  c.min_value = min_value;
  c.max_value = max_value;
  c.apply_initial_rule = apply_initial_rule;
  c.end_value = parse_end_value(end_value, "end_value");
  return c;
}

#define TEXEL_STAIRCASE_ARGS                                                                                    \
  py::arg("start_value"), py::arg("step_sizes"), py::kw_only(),                                                 \
      py::arg("n_up") = 1, py::arg("n_down") = 3, py::arg("n_reversals") = py::none(), py::arg("n_trials") = 0, \
      py::arg("step_type") = "lin", py::arg("min_value") = py::none(), py::arg("max_value") = py::none(),       \
      py::arg("apply_initial_rule") = true, py::arg("end_value") = "next"

#define TEXEL_BOX_ARGS                                                                                     \
  py::arg("pitch_min_db") = -20.0, py::arg("pitch_max_db") = 19.7, py::arg("irregularity_min_db") = -30.0, \
  py::arg("irregularity_max_db") = 5.0

GuidedConfig guided_config(double pmin, double pmax, double imin, double imax, int iterations, double shrink_rate,
                           const std::string& unsure, const std::string& bound, std::uint64_t seed) {
  GuidedConfig c;
  c.pitch_min_db = pmin;
  c.pitch_max_db = pmax;
  c.irregularity_min_db = imin;
  c.irregularity_max_db = imax;
  c.iterations = iterations;
  c.shrink_rate = shrink_rate;
  c.unsure = parse_unsure_mode(unsure, "unsure");
  c.bound = parse_bound_mode(bound, "bound");
  c.seed = seed;
  return c;
}

#define TEXEL_GUIDED_ARGS                                                                                               \
  py::kw_only(), TEXEL_BOX_ARGS, py::arg("iterations") = 5, py::arg("shrink_rate") = 0.2, py::arg("unsure") = "ignore", \
                                 py::arg("bound") = "per_axis", py::arg("seed") = std::uint64_t {                       \
    1                                                                                                                   \
  }

BayesConfig bayes_config(double pmin, double pmax, double imin, double imax, int comparisons, std::optional<double> sd_stop_db,
                         double noise_db, double unsure_band_db, double lapse, double irregularity_weight, double grid_step_db,
                         int candidates, int particles, std::uint64_t seed) {
  BayesConfig c;
  c.pitch_min_db = pmin;
  c.pitch_max_db = pmax;
  c.irregularity_min_db = imin;
  c.irregularity_max_db = imax;
  c.comparisons = comparisons;
  c.sd_stop_db = sd_stop_db;
  c.noise_db = noise_db;
  c.unsure_band_db = unsure_band_db;
  c.lapse = lapse;
  c.irregularity_weight = irregularity_weight;
  c.grid_step_db = grid_step_db;
  c.candidates = candidates;
  c.particles = particles;
  c.seed = seed;
  return c;
}

#define TEXEL_BAYES_ARGS                                                                                                         \
  py::kw_only(), TEXEL_BOX_ARGS, py::arg("comparisons") = 20, py::arg("sd_stop_db") = py::none(), py::arg("noise_db") = 2.0,     \
                                 py::arg("unsure_band_db") = 1.0, py::arg("lapse") = 0.04, py::arg("irregularity_weight") = 1.0, \
                                 py::arg("grid_step_db") = 0.5, py::arg("candidates") = 64, py::arg("particles") = 256,          \
                                 py::arg("seed") = std::uint64_t {                                                               \
    1                                                                                                                            \
  }

std::vector<double> box_column(const std::vector<MatchBox>& boxes, int which) {
  std::vector<double> v;
  for (const auto& b : boxes)
    v.push_back(which == 0   ? b.center.pitch_db
                : which == 1 ? b.center.irregularity_db
                : which == 2 ? b.pitch_half_db
                             : b.irregularity_half_db);
  return v;
}

}  // namespace

void register_experiment(py::module_& m) {
  // -------------------------------------------------------------- staircase
  py::class_<Staircase>(m, "Staircase", R"doc(Adaptive N-up/M-down staircase (PsychoPy StairHandler semantics), stepped:

    s = texel.Staircase(0.5, [0.1, 0.05], n_up=1, n_down=3, step_type='lin')
    while not s.finished:
        x = s.next()            # the intensity to present
        s.answer(correct)       # True / False

start_value        first intensity (never clamped); > 0 for log/db
step_sizes         step sizes in units of step_type (each > 0)
n_up, n_down       wrong / correct answers in a row that move the value up / down [1, 3]
n_reversals        reversals to finish (default and minimum: len(step_sizes))
n_trials           minimum number of trials [0]
step_type          'lin' (add), 'log' (×10^step) or 'db' (×10^(step/20)) ['lin']
min_value, max_value  clamps after moves down / up
apply_initial_rule 1-up/1-down until the first reversal [True]
end_value          the result (convergent_value): 'next' (computed after the last answer) or
                   'last-presented' (the source studies' "final value") ['next'])doc")
      .def(py::init([](double start_value, std::vector<double> step_sizes, int n_up, int n_down, std::optional<int> n_reversals,
                       int n_trials, const std::string& step_type, std::optional<double> min_value,
                       std::optional<double> max_value, bool apply_initial_rule, const std::string& end_value) {
             return Staircase(staircase_config(start_value, std::move(step_sizes), n_up, n_down, n_reversals, n_trials, step_type,
                                               min_value, max_value, apply_initial_rule, end_value));
           }),
           TEXEL_STAIRCASE_ARGS)
      .def_static(
          "replay",
          [](const std::vector<bool>& answers, double start_value, std::vector<double> step_sizes, int n_up, int n_down,
             std::optional<int> n_reversals, int n_trials, const std::string& step_type, std::optional<double> min_value,
             std::optional<double> max_value, bool apply_initial_rule, const std::string& end_value) {
            return Staircase::replay(staircase_config(start_value, std::move(step_sizes), n_up, n_down, n_reversals, n_trials,
                                                      step_type, min_value, max_value, apply_initial_rule, end_value),
                                     answers);
          },
          py::arg("answers"), TEXEL_STAIRCASE_ARGS,
          "Rebuilds a staircase from its answers (how a session resumes); raises InvalidArgument if an answer\n"
          "comes after it finished.")
      .def("next", &Staircase::next, "The intensity to present now (raises texel.Error when finished).")
      .def("answer", &Staircase::answer, py::arg("correct"), "The answer for the intensity next() returned.")
      .def_property_readonly("finished", &Staircase::finished)
      .def_property_readonly("trials", &Staircase::trials, "Answered trials.")
      .def_property_readonly(
          "intensities", [](const Staircase& s) { return std::vector<double>(s.intensities()); },
          "Presented intensities, one per answered trial.")
      .def_property_readonly("responses", [](const Staircase& s) { return std::vector<bool>(s.responses()); })
      .def_property_readonly(
          "reversal_trials", [](const Staircase& s) { return s.reversal_trials(); }, "0-based trial indices of the reversals.")
      .def_property_readonly("reversal_intensities", [](const Staircase& s) { return s.reversal_intensities(); })
      .def_property_readonly("last_was_reversal", &Staircase::last_was_reversal)
      .def_property_readonly("current_step", &Staircase::current_step, "Step size in force (units of step_type).")
      .def_property_readonly("convergent_value", &Staircase::convergent_value,
                             "The staircase's result by end_value: next_value ('next') or the last intensity presented "
                             "('last-presented').")
      .def_property_readonly("next_value", &Staircase::computed_value,
                             "The value computed after the last answer (what next() would present).")
      .def_property_readonly("n_reversals", &Staircase::n_reversals, "Effective number of reversals required.")
      .def("mean_last_reversals", &Staircase::mean_last_reversals, py::arg("k"),
           "Mean of the last min(k, n) reversal intensities.")
      .def("mean_reversals_excluding_first", &Staircase::mean_reversals_excluding_first, py::arg("k"))
      .def("state_json", &Staircase::state_json, "Compact JSON snapshot of the state (what the store records).");

  // ------------------------------------------------------ matching optimizers
  py::class_<MatchPoint>(m, "MatchPoint", "A point of the matching space: Central Pitch (dB re 1 cpm), Irregularity (dB).")
      .def(py::init([](double p, double i) {
             return MatchPoint{p, i};
           }),
           py::arg("pitch_db"), py::arg("irregularity_db"))
      .def(py::init([](const py::tuple& t) {
        if (t.size() != 2) throw py::value_error("MatchPoint: a tuple (pitch_db, irregularity_db) of two numbers");
        return MatchPoint{t[0].cast<double>(), t[1].cast<double>()};
      }))
      .def_readwrite("pitch_db", &MatchPoint::pitch_db)
      .def_readwrite("irregularity_db", &MatchPoint::irregularity_db)
      .def("__iter__", [](const MatchPoint& p) { return py::iter(py::make_tuple(p.pitch_db, p.irregularity_db)); })
      .def("__eq__", [](const MatchPoint& a, const MatchPoint& b) { return a == b; })
      .def("__repr__", [](const MatchPoint& p) {
        return "MatchPoint(pitch_db=" + std::to_string(p.pitch_db) + ", irregularity_db=" + std::to_string(p.irregularity_db) +
               ")";
      });
  py::implicitly_convertible<py::tuple, MatchPoint>();
  py::class_<MatchQuestion>(m, "MatchQuestion", "One comparison: which of a, b feels more like the reference?")
      .def_readonly("a", &MatchQuestion::a)
      .def_readonly("b", &MatchQuestion::b)
      .def_readonly("iteration", &MatchQuestion::iteration, "Guided: iteration (0-based); Bayesian: equals index.")
      .def_readonly("index", &MatchQuestion::index, "Comparison number (0-based).")
      .def("__repr__", [](const MatchQuestion& q) {
        return "<MatchQuestion " + std::to_string(q.index) + ": A=(" + std::to_string(q.a.pitch_db) + ", " +
               std::to_string(q.a.irregularity_db) + ") B=(" + std::to_string(q.b.pitch_db) + ", " +
               std::to_string(q.b.irregularity_db) + ")>";
      });
  py::class_<MatchOptimizer>(m, "MatchOptimizer", R"doc(A matching optimizer, stepped:

    while not opt.finished:
        q = opt.next()              # q.a, q.b: (pitch_db, irregularity_db)
        opt.answer('a')             # 'a', 'b' or 'unsure'
    opt.estimate                    # best match)doc")
      .def("next", &MatchOptimizer::next, "The next comparison (raises texel.Error when finished).")
      .def(
          "answer", [](MatchOptimizer& o, const std::string& c) { o.answer(choice_of(c)); }, py::arg("choice"),
          "The answer to next(): 'a', 'b' or 'unsure'.")
      .def_property_readonly("finished", &MatchOptimizer::finished)
      .def_property_readonly("estimate", &MatchOptimizer::estimate, "Current best match (dB).")
      .def_property_readonly("uncertainty", &MatchOptimizer::uncertainty,
                             "Per axis: box half-width (guided) or posterior SD (Bayesian), dB.")
      .def_property_readonly("comparisons", &MatchOptimizer::comparisons, "Answered comparisons.")
      .def_property_readonly("budget", &MatchOptimizer::budget, "Planned comparisons.")
      .def_property_readonly("name", &MatchOptimizer::name, "'guided' or 'bayesian'.")
      .def("state_json", &MatchOptimizer::state_json, "Compact JSON snapshot of the state.")
      .def(
          "replay",
          [](MatchOptimizer& o, const std::vector<std::string>& choices) {
            const auto cs = choices_of(choices);
            replay(o, cs);
          },
          py::arg("choices"), "Answers `choices` in order ('a' | 'b' | 'unsure').");
  py::class_<GuidedOptimizer, MatchOptimizer>(
      m, "GuidedOptimizer", "Guided exploration (Vardar's thesis): four comparisons per iteration, a shrinking box.")
      .def(py::init([](double pmin, double pmax, double imin, double imax, int it, double sr, const std::string& unsure,
                       const std::string& bound, std::uint64_t seed) {
             return GuidedOptimizer(guided_config(pmin, pmax, imin, imax, it, sr, unsure, bound, seed));
           }),
           TEXEL_GUIDED_ARGS)
      .def_property_readonly("iteration", &GuidedOptimizer::iteration, "Completed iterations.")
      .def_property_readonly("choices", [](const GuidedOptimizer& o) { return choice_names(o.choices()); })
      .def_property_readonly(
          "boxes",
          [](const GuidedOptimizer& o) {
            py::dict d;
            d["pitch_db"] = to_numpy(box_column(o.boxes(), 0));
            d["irregularity_db"] = to_numpy(box_column(o.boxes(), 1));
            d["pitch_half_db"] = to_numpy(box_column(o.boxes(), 2));
            d["irregularity_half_db"] = to_numpy(box_column(o.boxes(), 3));
            return d;
          },
          "Every box so far (initial, then one per iteration) as columns: centre and half-widths (dB).");
  py::class_<BayesOptimizer, MatchOptimizer>(m, "BayesOptimizer",
                                             "Bayesian matching: grid posterior, next pair by expected information gain.")
      .def(py::init([](double pmin, double pmax, double imin, double imax, int comparisons, std::optional<double> sd_stop,
                       double noise, double band, double lapse, double w, double grid, int candidates, int particles,
                       std::uint64_t seed) {
             py::gil_scoped_release release;  // plans the first question
             return BayesOptimizer(bayes_config(pmin, pmax, imin, imax, comparisons, sd_stop, noise, band, lapse, w, grid,
                                                candidates, particles, seed));
           }),
           TEXEL_BAYES_ARGS)
      .def(
          "likelihood",
          [](const BayesOptimizer& o, const MatchQuestion& q, const std::string& c, const MatchPoint& t) {
            return o.likelihood(q, choice_of(c), t);
          },
          py::arg("question"), py::arg("choice"), py::arg("target"), "P(choice | target) under the optimizer's model.")
      .def_property_readonly("choices", [](const BayesOptimizer& o) { return choice_names(o.choices()); });
  m.def(
      "optimizer",
      [](const std::string& kind, const py::kwargs& params) {
        const auto text = py::module_::import("json").attr("dumps")(params).cast<std::string>();
        return make_optimizer(parse_optimizer_kind(kind, "kind"), text);
      },
      py::arg("kind"),
      "A matching optimizer from protocol parameters: kind 'guided' | 'bayesian', keyword arguments as the\n"
      "protocol's keys (unknown keys raise InvalidArgument naming them).");

  // -------------------------------------------------------------- observers
  py::class_<PsychometricObserver>(m, "PsychometricObserver",
                                   "A simulated observer p(x) = γ + (1 − γ − λ)·F(x) (Weibull or logistic), seeded.")
      .def(py::init([](const std::string& shape, double threshold, double slope, double guess, double lapse, bool log_x,
                       std::uint64_t seed) {
             return PsychometricObserver(
                 PsychometricConfig{parse_psychometric_shape(shape, "shape"), threshold, slope, guess, lapse, log_x, seed});
           }),
           py::kw_only(), py::arg("shape") = "weibull", py::arg("threshold") = 1.0, py::arg("slope") = 3.0,
           py::arg("guess") = 0.0, py::arg("lapse") = 0.0, py::arg("log_x") = false, py::arg("seed") = std::uint64_t{1})
      .def("p_correct", &PsychometricObserver::p_correct, py::arg("x"))
      .def("inverse", &PsychometricObserver::inverse, py::arg("p"), "The x where p_correct(x) = p.")
      .def("respond", &PsychometricObserver::respond, py::arg("x"), py::arg("trial"),
           "A seeded Bernoulli answer (True = correct) for intensity x on trial `trial`.")
      .def("respond_with", &PsychometricObserver::respond_with, py::arg("p"), py::arg("trial"));
  py::class_<Matcher>(m, "Matcher", "A simulated matching participant: noisy perceptual distances to a hidden target (dB).")
      .def(py::init([](const MatchPoint& target, double noise, double band, double w, double pmin, double pmax, double imin,
                       double imax, std::uint64_t seed) {
             return Matcher(MatcherConfig{target, noise, band, w, pmin, pmax, imin, imax, seed});
           }),
           py::arg("target"), py::kw_only(), py::arg("noise_db") = 2.0, py::arg("unsure_band_db") = 1.0,
           py::arg("irregularity_weight") = 1.0, TEXEL_BOX_ARGS, py::arg("seed") = std::uint64_t{1})
      .def("distance", &Matcher::distance, py::arg("point"))
      .def(
          "choose",
          [](const Matcher& mt, const MatchQuestion& q, std::uint64_t trial) {
            return std::string(to_string(mt.choose(q, trial)));
          },
          py::arg("question"), py::arg("trial"), "'a', 'b' or 'unsure' for a comparison on trial `trial`.")
      .def("adjust", &Matcher::adjust, py::arg("trial"), "A slider match: target + noise, clamped to the box.")
      .def("confidence", &Matcher::confidence, py::arg("trial"), "1 … 5.");
  py::class_<Rater>(m, "Rater", "A simulated similarity rater: exponential decay with distance plus rating noise.")
      .def(py::init([](double smin, double smax, double d, double noise, std::uint64_t seed) {
             return Rater(RaterConfig{smin, smax, d, noise, seed});
           }),
           py::kw_only(), py::arg("scale_min") = 1.0, py::arg("scale_max") = 5.0, py::arg("distance_scale_db") = 10.0,
           py::arg("noise") = 0.5, py::arg("seed") = std::uint64_t{1})
      .def("expected", &Rater::expected, py::arg("distance_db"))
      .def("rate", &Rater::rate, py::arg("distance_db"), py::arg("trial"));
  m.def(
      "perceptual_target",
      [](const std::string& reference, const std::string& device) {
        py::gil_scoped_release release;
        return perceptual_target(reference, device);
      },
      py::arg("reference"), py::arg("device") = "tpad",
      "The (Central Pitch, Irregularity) of a reference under the encoder's perceptual model (about 1 s).");

  // ------------------------------------------------------------------ store
  py::class_<StoreHandle, std::shared_ptr<StoreHandle>>(m, "Store",
                                                        R"doc(A session database (SQLite): sessions, trials and long-format rows.

    with texel.Store("cohort.db") as store:     # closed at the end of the block
        rows = store.rows(columns=True)

mode  'r': read-only, never creates or writes (default); 'rw': read-write, created if missing
      (what experiment.Session records into). close() ends the connection; unless another
      program has the database open, it then holds no -wal/-shm files.
path  may also name a PostgreSQL server ("postgresql://station1@db/study" or "service=NAME";
      password from ~/.pgpass): 'r' reads the server, 'rw' makes this process a station that
      stores every trial in its local journal first (journal=PATH, or the default of
      docs/session-store.md) and ships it in the background.)doc")
      .def(py::init([](const py::object& path, const std::string& mode, const std::optional<std::string>& journal) {
             if (mode != "r" && mode != "rw") throw InvalidArgument("mode is '" + mode + "'; allowed: r, rw");
             const StoreMode sm = mode == "r" ? StoreMode::read_only : StoreMode::read_write;
             return std::make_shared<StoreHandle>(Store::open(path_of(path), sm, StoreOptions{journal.value_or("")}), sm);
           }),
           py::arg("path"), py::arg("mode") = "r", py::arg("journal") = py::none())
      .def("close", &StoreHandle::close, "Closes the database (again: nothing).")
      .def_property_readonly(
          "closed", [](const StoreHandle& h) { return !h.store; }, "True after close().")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](StoreHandle& h, const py::args&) { h.close(); })
      .def_property_readonly("schema_version", [](StoreHandle& h) { return h.get().schema_version(); })
      .def_property_readonly("path", [](StoreHandle& h) { return h.get().path(); })
      .def("participants", [](StoreHandle& h) { return h.get().participants(); })
      .def(
          "sessions",
          [](StoreHandle& h) {
            const Store& s = h.get();
            py::list l;
            for (const auto& x : s.sessions()) l.append(session_dict(x));
            return l;
          },
          "Every session as a dict: the fields of `texel experiment list --json` (id, participant, protocol,\n"
          "study, status, trials_done, trials_planned (-1 = adaptive), seed, …) and protocol_json.")
      .def(
          "session", [](StoreHandle& h, std::int64_t id) { return session_dict(h.get().session(id)); }, py::arg("session_id"))
      .def(
          "session_json", [](StoreHandle& h, std::int64_t id) { return to_json(h.get().session(id)); }, py::arg("session_id"),
          "The session as JSON text, exactly as `texel experiment list --json` and the studio write it.")
      .def(
          "trials",
          [](StoreHandle& h, std::int64_t id) {
            const Store& s = h.get();
            py::list l;
            for (const auto& t : s.trials(id)) {
              py::dict d;
              d["trial"] = t.trial;
              d["question_json"] = t.question_json;
              d["response_json"] = t.response_json;
              d["state_json"] = t.state_json;
              d["row"] = rows_records({t.row})[0];
              py::list events;
              for (const auto& e : t.events) {
                py::dict ed;
                ed["t_s"] = e.t_s;
                ed["kind"] = e.kind;
                ed["detail"] = e.detail;
                ed["at"] = e.at;
                events.append(ed);
              }
              d["events"] = events;
              l.append(d);
            }
            return l;
          },
          py::arg("session_id"), "Every stored trial of a session: question, response, state (JSON text), row, events.")
      .def(
          "rows",
          [](StoreHandle& h, std::optional<std::int64_t> id, bool as_columns) { return rows_py(h.get().rows(id), as_columns); },
          py::arg("session_id") = py::none(), py::kw_only(), py::arg("columns") = false,
          "Long-format rows (the export CSV's), as a list of dicts (columns=False) or a dict of numpy\n"
          "columns (columns=True; pandas.DataFrame accepts either). Missing numbers are NaN.");
  m.def(
      "read_trials",
      [](const py::object& path, std::optional<std::int64_t> id, bool as_columns) {
        StoreHandle h(Store::open(path_of(path), StoreMode::read_only), StoreMode::read_only);
        py::object rows = rows_py(h.get().rows(id), as_columns);
        h.close();
        return rows;
      },
      py::arg("path"), py::arg("session_id") = py::none(), py::kw_only(), py::arg("columns") = false,
      "The rows of a session database, as `texel experiment export` writes them (see Store.rows).");
  m.def("trial_columns", &trial_columns, "Column names of the long-format rows, in export order.");
}

}  // namespace texel::python
