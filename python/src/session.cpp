// Binding of the session runner (texel/experiment/runner.hpp, session.hpp,
// presenter.hpp) as texel._texel.experiment, re-exported by
// texel/experiment.py: open or resume a participant's session on a Store,
// read the current question, present its stimuli on a player backend,
// record the answer (committed before the next question exists). The engine
// owns the procedure; the caller owns the loop and the window, so a PsychoPy
// script runs Texel's procedures and stimuli inside its own event loop.
//
// Questions and responses cross as JSON (Question::to_json,
// Response::from_json): the glue stays a few lines when the engine's structs
// grow, and a dict is what a Python caller wants anyway.
#include <chrono>
#include <filesystem>
#include <thread>

#include "common.hpp"
#include "options.hpp"
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/runner.hpp"
#include "texel/experiment/store.hpp"
#include "texel/io.hpp"

namespace texel::python {
namespace {

using namespace texel::experiment;

py::object from_json(const std::string& text) { return py::module_::import("json").attr("loads")(text); }
std::string to_json(const py::handle& value) { return py::module_::import("json").attr("dumps")(value).cast<std::string>(); }

// A protocol from a path, JSON text or a dict (the protocol file's content).
Protocol protocol_of(const py::handle& protocol) {
  if (py::isinstance<py::dict>(protocol)) return parse_protocol(to_json(protocol), "protocol");
  if (py::isinstance<py::str>(protocol)) {
    const auto text = protocol.cast<std::string>();
    if (text.find('{') != std::string::npos) return parse_protocol(text, "protocol");
  }
  return load_protocol(path_of(protocol));
}

// A stimulus document as JSON text: a question's stimulus dict
// ({"label", "document"}), a document dict, a Document or JSON text.
std::string document_text(const py::handle& d) {
  if (py::isinstance<Document>(d)) return document_json(d.cast<const Document&>());
  if (py::isinstance<py::str>(d)) return d.cast<std::string>();
  if (py::isinstance<py::dict>(d)) {
    const auto dict = py::reinterpret_borrow<py::dict>(d);
    return to_json(dict.contains("document") ? dict["document"] : dict);
  }
  throw py::type_error("a stimulus is a question's stimulus dict, a document dict, a texel.Document or JSON text");
}

class PySession {
 public:
  PySession(std::shared_ptr<StoreHandle> store, const py::object& protocol, const std::string& participant, bool resume,
            std::optional<std::string> simulate)
      : store_(std::move(store)) {
    if (store_->mode != StoreMode::read_write) throw InvalidArgument("store: a session records; open it with mode='rw'");
    OpenOptions o;
    o.participant = participant;
    o.resume = resume;
    o.simulate = std::move(simulate);
    try {
      active_.emplace(open_session(store_->get(), protocol_of(protocol), o));
    } catch (const SessionConflict& e) {  // how to do the other thing, in Python's words
      throw InvalidArgument(std::string(e.what()) + (e.kind() == SessionConflict::Kind::unfinished_exists
                                                         ? " (Session(..., resume=True))"
                                                         : " (start one with resume=False)"));
    }
  }

  ActiveSession& active() {
    if (!active_) throw InvalidArgument("the session is closed");
    return *active_;
  }
  void close() { active_.reset(); }
  [[nodiscard]] bool closed() const { return !active_; }

  // Reading the question hands it out: its clock starts (onset) on the first read.
  py::object question() {
    ActiveSession& a = active();
    if (!a.session.finished()) (void)hand_out(a);
    return from_json(a.session.question().to_json());
  }

  py::dict handout() {
    const Handout h = hand_out(active());
    py::dict d = from_json(texel::experiment::to_json(h));
    d["trial"] = h.trial;  // the 0-based index too, for scripts that key trials by it
    return d;
  }

  Document stimulus(std::size_t i) {
    const Question& q = active().session.question();
    if (i >= q.stimuli.size())
      throw InvalidArgument("stimulus is " + std::to_string(i) + "; this question has " + std::to_string(q.stimuli.size()));
    return parse_document(q.stimuli[i].document_json, "stimulus " + q.stimuli[i].label);
  }

  // The first presentation of a trial prepares the presenter for it (a
  // display that stores maps gets the trial's stimuli; the finger trace
  // starts), as the terminal runner does; record() stores that trace.
  void present(const py::object& presenter_object, std::size_t i) {
    auto& presenter = presenter_object.cast<Presenter&>();
    ActiveSession& a = active();
    const Question& q = a.session.question();
    if (i >= q.stimuli.size())
      throw InvalidArgument("stimulus is " + std::to_string(i) + "; this question has " + std::to_string(q.stimuli.size()));
    if (!traced() || traced_trial_ != q.trial || !traced_.is(presenter_object)) {
      presenter.prepare(q);
      traced_ = presenter_object;
      traced_trial_ = q.trial;
    }
    presenter.show(q.stimuli[i].document_json);
    if (shown_at_.empty()) shown_at_ = utc_timestamp();
  }

  py::object simulated_response() {
    ActiveSession& a = active();
    if (a.simulate.empty()) throw InvalidArgument("simulated_response: the session was opened without simulate=");
    return from_json(simulated_participant(a).respond(a.session).to_json());
  }

  // The token path (runner.hpp): without a token, the current question's.
  py::dict record(const py::object& response, const std::optional<std::string>& token) {
    ActiveSession& a = active();
    Response r = Response::from_json(to_json(response));
    if (r.shown_at.empty()) r.shown_at = shown_at_;
    // The finger that explored this trial on the presenter it was played on.
    if (traced() && !a.session.finished() && traced_trial_ == a.session.question().trial)
      r.trace = traced_.cast<Presenter&>().take_trace();
    const std::string t_token = token ? *token : hand_out(a).token;
    const StoredTrial t = experiment::record(store_->get(), &a, t_token, std::move(r));  // committed before it returns
    shown_at_.clear();
    traced_ = py::object();
    return rows_records({t.row})[0].cast<py::dict>();
  }

 private:
  std::shared_ptr<StoreHandle> store_;
  std::optional<ActiveSession> active_;
  std::string shown_at_;  // when the current question's first stimulus was presented
  py::object traced_;     // the Presenter prepared for the current trial (null: none yet)
  [[nodiscard]] bool traced() const { return static_cast<bool>(traced_); }
  int traced_trial_ = -1;
};

PresenterOptions presenter_options(const std::string& backend, double rate_hz, double swipe_speed_mm_s,
                                   const std::string& audio_device, const std::string& response,
                                   const std::optional<std::string>& mode, std::size_t channels) {
  PresenterOptions o;
  o.channels = channels;
  if (mode) o.mode = parse_presentation_mode(*mode, "mode");
  o.backend = backend;
  o.rate_hz = rate_hz;
  o.swipe_speed_mm_s = swipe_speed_mm_s;
  o.audio_device = audio_device;
  o.response_handling = parse_response_handling(response, "response");
  return o;
}

}  // namespace

void register_session(py::module_& root) {
  py::module_ m = root.def_submodule("experiment", "Running a protocol's sessions (texel.experiment).");

  py::class_<Presenter>(m, "Presenter", R"doc(Plays stimuli on a player backend, as `texel experiment run --backend`.

backend           'null' (plays into nothing, paced by the clock), 'audio' (the sound card: actuators)
                  or 'serial:PATH' (a surface-haptic display) ['null']
rate_hz           output rate of 'null' / 'audio' (Hz) [48000]
swipe_speed_mm_s  the simulated finger's speed where the backend senses none (mm/s) [100]
audio_device      PortAudio device index or name part ['' = default]
response          'limit' (never drive what the display attenuates by 20 dB or more) or 'off' ['limit']
mode              how stimuli reach the finger: 'display-plays' (a serial display that stores maps
                  plays them from its own finger sensor), 'host-streams' (the host streams the
                  output from the display's reported finger) or 'passive' (a simulated sweep, where
                  no finger exists) [None: what the display's HELLO allows, in that order]
channels          output channels, one per actuator of a multi-actuator display ('null', 'audio'):
                  presentation_channels(protocol's device) [1]

Call pump() often (every ≤ 20 ms) from the loop that owns the window; close() (or the end of
a with block) stops the backend.)doc")
      .def(py::init([](const std::string& backend, double rate_hz, double swipe_speed_mm_s, const std::string& audio_device,
                       const std::string& response, const std::optional<std::string>& mode, std::size_t channels) {
             return std::make_unique<Presenter>(
                 presenter_options(backend, rate_hz, swipe_speed_mm_s, audio_device, response, mode, channels));
           }),
           py::arg("backend") = "null", py::kw_only(), py::arg("rate_hz") = 48000.0, py::arg("swipe_speed_mm_s") = 100.0,
           py::arg("audio_device") = "", py::arg("response") = "limit", py::arg("mode") = py::none(), py::arg("channels") = 1)
      .def_property_readonly("channels", &Presenter::channels, "Output channels (one per actuator).")
      .def_property_readonly(
          "mode", [](const Presenter& p) { return std::string(to_string(p.mode())); },
          "The presentation mode in force: 'display-plays', 'host-streams' or 'passive'.")
      .def(
          "show", [](Presenter& p, const py::object& stimulus) { p.show(document_text(stimulus)); }, py::arg("stimulus"),
          "Plays a stimulus: a question's stimulus dict, a document dict, a texel.Document or JSON text.")
      .def("blank", &Presenter::blank, "Silence (between trials).")
      .def("pump", &Presenter::pump, "Feeds the simulated finger and frees retired maps; call every ≤ 20 ms.")
      .def(
          "wait",
          [](Presenter& p, double seconds) {
            // Pumping while waiting, as the terminal runner does.
            const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
            py::gil_scoped_release release;
            while (std::chrono::steady_clock::now() < end) {
              p.pump();
              std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
          },
          py::arg("seconds"), "Waits `seconds`, pumping (a loop without its own clock).")
      .def("close", &Presenter::stop, "Stops the backend (again: nothing).")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](Presenter& p, const py::args&) { p.stop(); })
      .def("describe", &Presenter::describe, "The backend, as the runner reports it.")
      .def_property_readonly("shown", &Presenter::shown, "Stimuli shown so far.")
      .def_property_readonly("error", &Presenter::error, "An error the backend reported ('' if none).")
      .def_property_readonly(
          "stats",
          [](Presenter& p) {
            const BackendStats s = p.stats();
            py::dict d;
            d["blocks"] = s.blocks;
            d["worst_block_ms"] = s.worst_block_s * 1e3;
            d["late_blocks"] = s.underruns;
            return d;
          },
          "Blocks processed, the worst block (ms), late blocks.")
      .def("__repr__", [](const Presenter& p) { return "<texel.experiment.Presenter " + p.describe() + ">"; });

  py::class_<PySession>(m, "Session", R"doc(A participant's session of a protocol, stepped — the engine the terminal
runner and the studio drive:

    with texel.Store("study.db", mode="rw") as store, \
         texel.experiment.Session(store, "protocol.json", "P01") as s, \
         texel.experiment.Presenter("null") as player:
        while not s.finished:
            q = s.question                  # dict: prompt, stimuli, choices, rating_scale, sliders, ...
            s.present(player, 0)            # play stimulus 0 (the participant may switch freely)
            s.record({"choice": q["choices"][0], "rt_ms": 850})   # committed before the next question

store        a texel.Store opened with mode="rw"
protocol     a protocol file path, its JSON text or a dict of it
participant  the participant code (1–32 of A–Z a–z 0–9 _ . -)
resume       continue the participant's unfinished session (error if none; without it, an
             unfinished one is an error) [False]
simulate     a simulation spec ('default' or as --simulate): simulated_response() answers for a
             simulated participant; on resume, None keeps the stored one [None]
close() (or the end of a with block) releases the session; what was recorded stays stored and a
later Session(..., resume=True) continues where it stopped.)doc")
      .def(py::init<std::shared_ptr<StoreHandle>, const py::object&, const std::string&, bool, std::optional<std::string>>(),
           py::arg("store"), py::arg("protocol"), py::arg("participant"), py::kw_only(), py::arg("resume") = false,
           py::arg("simulate") = py::none())
      .def_property_readonly(
          "finished", [](PySession& s) { return s.active().session.finished(); }, "True when every trial is recorded.")
      .def_property_readonly(
          "question", &PySession::question,
          "The current question as a dict (participant-safe: never the answer); raises texel.Error when finished.\n"
          "The first read of a trial's question is its onset: the library's clock (handout) starts there.")
      .def_property_readonly(
          "trials_done", [](PySession& s) { return s.active().session.trials_done(); }, "Trials recorded.")
      .def_property_readonly(
          "trials_planned",
          [](PySession& s) -> std::optional<int> {
            const int n = s.active().session.trials_planned();
            return n >= 0 ? std::optional<int>(n) : std::nullopt;
          },
          "Planned trials; None when adaptive.")
      .def_property_readonly(
          "id", [](PySession& s) { return s.active().info.id; }, "The session's id in the store.")
      .def_property_readonly(
          "info", [](PySession& s) { return session_dict(s.active().info); },
          "The session's record when it was opened (as Store.session).")
      .def("stimulus", &PySession::stimulus, py::arg("index"),
           "Stimulus `index` of the current question as a texel.Document (render() it for your own output).")
      .def("present", &PySession::present, py::arg("presenter"), py::arg("index") = 0,
           "Plays stimulus `index` of the current question on a Presenter. The trial's first call stamps\n"
           "shown_at and prepares the presenter (a display that stores maps gets the trial's stimuli; the\n"
           "finger trace starts); record() stores that trace and its swipe measures with the trial.")
      .def("simulated_response", &PySession::simulated_response,
           "The simulated participant's answer to the current question (sessions opened with simulate=).")
      .def("record", &PySession::record, py::arg("response"), py::arg("token") = py::none(),
           "Answers the current question — a dict with the fields it asks for: choice, rating, confidence,\n"
           "slider_p, slider_i, digit, rt_ms, events, shown_at, answered_at — stores the trial durably and\n"
           "returns its long-format row. Raises InvalidArgument (nothing stored) for an answer that does not fit.\n"
           "token: the handout's token of the question answered (default: the current one); an answer whose\n"
           "token is stale, or given while suspended, is refused (InvalidArgument, nothing stored). rt_ms\n"
           "defaults to the library's clock: from the first read of the question, without suspended time.")
      .def_property_readonly("handout", &PySession::handout,
                             "The current question's token and clock: token, trial, trial_number (1-based), attempt,\n"
                             "onset_at, elapsed_s (without suspended time), time_limit_s, suspended.")
      .def(
          "suspend", [](PySession& s) { suspend(s.active()); },
          "Pauses the session: answers are refused and the trial's clock stops until resume().")
      .def(
          "resume", [](PySession& s) { resume(s.active()); }, "Continues a paused session (the same trial, its clock intact).")
      .def("close", &PySession::close, "Releases the session (again: nothing).")
      .def_property_readonly("closed", &PySession::closed)
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](PySession& s, const py::args&) { s.close(); })
      .def("__repr__", [](PySession& s) {
        if (s.closed()) return std::string("<texel.experiment.Session closed>");
        const ActiveSession& a = s.active();
        const int planned = a.session.trials_planned();
        return "<texel.experiment.Session " + std::to_string(a.info.id) + ": " + a.info.protocol + " for " + a.info.participant +
               ", " + std::to_string(a.session.trials_done()) + (planned >= 0 ? "/" + std::to_string(planned) : "") + " trials" +
               (a.session.finished() ? ", finished>" : ">");
      });

  m.def(
      "presentation_channels", [](const py::object& protocol) { return presentation_channels(protocol_of(protocol)); },
      py::arg("protocol"),
      "The output channels a session of `protocol` plays on: one per actuator of its device (1 without);\n"
      "Presenter(channels=...).");
  m.def(
      "simulate_cohort",
      [](const std::shared_ptr<StoreHandle>& store, const py::object& protocol, const std::vector<std::string>& participants,
         const std::string& spec) { return simulate_cohort(store->get(), protocol_of(protocol), participants, spec); },
      py::arg("store"), py::arg("protocol"), py::arg("participants"), py::kw_only(), py::arg("simulate") = "default",
      "Runs simulated participants through a protocol to the end (resuming unfinished ones), as\n"
      "`texel experiment cohort`; returns their session ids.");
  m.def(
      "analyze",
      [](const std::optional<py::object>& db, const std::optional<py::object>& csv, const std::optional<py::object>& out_dir,
         const py::kwargs& kwargs) {
        if (db.has_value() == csv.has_value()) throw InvalidArgument("analyze: give exactly one of db= or csv=");
        AnalysisOptions o;
        set_options(o, kwargs, "analyze");
        if (out_dir) o.out_dir = path_of(*out_dir);
        const std::vector<TrialRow> rows = db ? Store::open(path_of(*db), StoreMode::read_only).rows()
                                              : parse_trials_csv(read_file(path_of(*csv)), path_of(*csv));
        const AnalysisReport report = analyze(rows, o);
        py::dict r;
        r["summary"] = py::module_::import("json").attr("loads")(report.summary);
        r["text"] = report.text;
        r["figures"] = report.figures;
        r["tables"] = report.tables;
        return r;
      },
      py::kw_only(), py::arg("db") = py::none(), py::arg("csv") = py::none(), py::arg("out_dir") = py::none(),
      "Per-study summaries and figures of a session database (db=) or an exported CSV (csv=), as\n"
      "`texel experiment analyze`; figures into out_dir when given. The options are the library's\n"
      "(analysis_options() lists them with their defaults and ranges). Returns a dict: summary (the\n"
      "JSON summary), text, figures and tables (paths written).");
  m.def(
      "analysis_options", [] { return options_list(AnalysisOptions{}); },
      "The options of analyze(), as the library describes them: key, flag (the CLI's), help, default and\n"
      "range or choices, in the CLI's order.");
}

}  // namespace texel::python
