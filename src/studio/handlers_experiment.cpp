// Experiment messages (FIFO lane, one session at a time): thin calls into the
// experiment engine's step-wise API (experiment/runner.hpp) and its store;
// every rule of a study lives there.
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "base64.hpp"
#include "messages.hpp"
#include "texel/device.hpp"
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/experiment/export_mat.hpp"
#include "texel/experiment/session_state.hpp"
#include "texel/experiment/strokes.hpp"
#include "texel/experiment/surface_maps.hpp"
#include "texel/matfile.hpp"
#include "texel/serial_link.hpp"
#include "texel/surface2d.hpp"

namespace texel::studio::detail {

namespace ex = texel::experiment;

// The participant's strokes of a 2-D trial (task oddity-2d; docs/studio.md
// "2-D studies"): the page is the touch surface, its samples drive the 2-D
// pad's player on the studio's device and are summarised per interval by
// the library's StrokeRecorder, as the terminal's 2-D display presenter
// does, and stored with the answer. Bound to one hand-out token: a new
// question (or a restarted trial) starts from no strokes.
struct Strokes2DState {
  std::string token;                                    // the hand-out these strokes belong to
  int selected = -1;                                    // the interval playing (index into Question::stimuli)
  std::map<std::string, ex::StrokeRecorder> recorders;  // by stimulus label
  double last_t_s = 0.0;                                // the newest sample, page seconds
  // The page's clock onto the player's, for one page (a reloaded page's clock starts again).
  ReportTimeline timeline;
  std::uint64_t page = 0;  // the connection whose clock the timeline follows
  // The session's interval maps, the library's (surface_maps.hpp): its friction
  // bitmaps are preloaded from the moment the session opens. Null until then.
  std::unique_ptr<ex::SurfaceMaps> maps;
};

std::shared_ptr<Strokes2DState> make_strokes2d_state() { return std::make_shared<Strokes2DState>(); }

namespace {

constexpr std::size_t max_stroke_samples = 512;  // per experiment.stroke message
constexpr double page_lead_s = 0.005;            // as the 2-D pad's finger: a sample is due this long after it arrives
const ex::StrokeRules stroke_rules{};            // the terminal presenter's defaults (docs/experiments.md)

/// The strokes of the question in force: reset when its token changes.
Strokes2DState& strokes_of(State& s) {
  Strokes2DState& st = *s.strokes2d;
  const std::string token = ex::peek(*s.active).token;
  if (st.token != token) {
    st.token = token;
    st.selected = -1;
    st.recorders.clear();
    st.last_t_s = 0.0;
    st.timeline = ReportTimeline{};
    st.page = 0;
  }
  return st;
}

/// The player map of a 2-D interval (path-indexed, or the static field's friction bitmap, rendered once).
std::unique_ptr<const PlayerMap2D> surface_map(Strokes2DState& st, const ex::SurfaceStimulus& s) {
  if (!st.maps) st.maps = std::make_unique<ex::SurfaceMaps>();
  return st.maps->map(s);
}

/// Renders a 2-D question's bitmaps unless the preload has them (as the
/// terminal prepares them before the trial's clock starts), so its onset, and
/// so its reaction time, does not include a rendering and switching intervals
/// costs a copy.
void prepare_surfaces(State& s, const ex::Question& q) {
  Strokes2DState& st = *s.strokes2d;
  if (!st.maps) st.maps = std::make_unique<ex::SurfaceMaps>();
  st.maps->prepare(q);
}

/// The session's bitmaps rendered in the background from now (a simulated session feels nothing).
void preload_surfaces(State& s) {
  Strokes2DState& st = *s.strokes2d;
  st.maps = std::make_unique<ex::SurfaceMaps>();  // the previous session's preload ends
  if (s.active->simulate.empty()) st.maps->preload(s.active->session.protocol(), s.active->session.context());
}

/// The question's intervals as the participant stroked them (one per stimulus, as Presenter::strokes).
std::vector<ex::IntervalStrokes> stroke_summaries(const Strokes2DState& st, const ex::Question& q) {
  std::vector<ex::IntervalStrokes> out;
  for (std::size_t i = 0; i < q.stimuli.size(); ++i) {
    const std::string& label = q.stimuli[i].label;
    const double direction = q.surfaces[i].direction_deg;
    const auto it = st.recorders.find(label);
    out.push_back(it == st.recorders.end() ? ex::StrokeRecorder(stroke_rules).summary(label, direction)
                                           : it->second.summary(label, direction));
  }
  return out;
}

/// "1" → "texture 1"; named stimuli keep their name (as the participant page says them).
std::string stimulus_words(const std::string& label) {
  const bool digits = !label.empty() && std::all_of(label.begin(), label.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
  return digits ? "texture " + label : label;
}

/// The surface a 2-D question is stroked on: its size (the same display for every interval; nothing of the trial).
ojson surface_size_json(const ex::Question& q) {
  const Document doc = parse_document(q.surfaces.front().document_json, "stimulus surface");
  if (!doc.device.bitmap) return ojson(nullptr);
  return ojson{{"width_mm", doc.device.bitmap->width_mm().value()}, {"height_mm", doc.device.bitmap->height_mm().value()}};
}

ex::Store& the_store(State& s) {
  if (!s.store) s.store.emplace(ex::Store::open(s.options.db_path, ex::StoreMode::read_write));
  return *s.store;
}

struct Shipped {
  std::string file;
  ex::Protocol protocol;
};

std::vector<Shipped> shipped_protocols(const State& s) {
  std::vector<Shipped> out;
  if (s.options.protocols_dir.empty()) return out;
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(s.options.protocols_dir, ec))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& p : files) {
    try {
      out.push_back({p.filename().string(), ex::load_protocol(p.string())});
    } catch (const Error&) {
      // A broken shipped file is the CLI's to report (texel experiment validate), not a client's.
    }
  }
  return out;
}

// The running session as the library serialises it (as stored now), with
// "simulated" for the spec in force.
ojson session_json(State& s) {
  const ex::SessionInfo info = the_store(s).session(s.active->info.id);
  ojson j = ojson::parse(ex::to_json(info));
  j["state"] = ex::to_string(ex::session_state(info, true, s.active->suspended));
  j["simulated"] = !s.active->simulate.empty();
  return j;
}

ojson progress_json(const State& s) {
  return ojson{{"done", s.active->session.trials_done()}, {"planned", s.active->session.trials_planned()}};
}

// What participant screens may see of a question (the library's participant view:
// no block, no documents), with a show_maps question's maps as rendered
// float32 samples (map_f32) to draw: the maps, not the parameters and seeds
// they were made from.
ojson participant_question(const ex::Question& q) {
  ojson j = ojson::parse(q.participant_json());
  if (q.show_maps)
    for (std::size_t i = 0; i < q.stimuli.size(); ++i) {
      const auto map = PlayerMap::from_document(parse_document(q.stimuli[i].document_json, "stimulus"));
      const std::span<const float> v = map->values();
      j["stimuli"][i]["map_f32"] =
          base64_encode(std::span(reinterpret_cast<const unsigned char*>(v.data()), v.size() * sizeof(float)));
    }
  return j;
}

/// The strip a 1-D question is felt on: the protocol's device length (mm), nothing of the trial.
std::optional<double> strip_length_mm(const State& s) {
  try {
    return load_device(s.active->session.protocol().device).length().value();
  } catch (const Error&) {
    return std::nullopt;
  }
}

ojson handout_json(const ex::Handout& h) { return ojson::parse(ex::to_json(h)); }

// The state participant screens show: the question (with its token and
// clock), suspended, finished or idle. `screen`: for a participant screen
// (the hand-out starts the trial's clock); `reload`: that screen was (re)loaded.
ojson current_state(State& s, const json& id, bool screen, bool reload = false) {
  if (!s.active) return reply("experiment.idle", id);
  const char* type = s.active->session.finished() ? "experiment.finished"
                     : s.active->suspended        ? "experiment.suspended"
                                                  : "experiment.question";
  ojson r = reply(type, id);
  // Only a direct reply to the experimenter's side carries the session (its participant code,
  // protocol, seed): never a participant screen, nor a push, which every connection of a
  // participant's browser gets (the page's finger worker too).
  if (!screen && !id.is_null()) r["session"] = session_json(s);
  r["progress"] = progress_json(s);
  if (!s.active->session.finished() && !s.active->suspended) {
    const ex::Question& q = s.active->session.question();
    r["question"] = participant_question(q);
    if (!q.surfaces.empty())
      r["surface"] = surface_size_json(q);  // the page is the touch surface
    else if (const auto mm = strip_length_mm(s))
      r["strip_mm"] = *mm;
    if (screen && s.active->simulate.empty()) prepare_surfaces(s, q);  // before the hand-out starts the trial's clock
    if (!screen && s.strokes2d->maps && !q.surfaces.empty()) {
      // The experimenter's view: bitmaps the preload rendered, and those a participant waited for.
      const ex::SurfaceMaps::Counts n = s.strokes2d->maps->counts();
      r["bitmaps"] = ojson{
          {"preloaded", s.strokes2d->maps->preloaded()}, {"rendered_ahead", n.preloaded}, {"rendered_at_handout", n.at_trial}};
    }
    r["handout"] = handout_json(!screen ? ex::peek(*s.active) : reload ? ex::reload(*s.active) : ex::hand_out(*s.active));
  }
  return r;
}

// Every other screen follows the session (the requester has its reply).
void tell_everyone(State& s, const Client& requester) {
  if (s.broadcast) s.broadcast([&](bool screen) { return current_state(s, json(nullptr), screen); }, requester.id);
}

const ex::Question& current_question(const State& s, const Fields& f, const std::string& type) {
  if (!s.active) throw Reject{"not_found", type + ": no session is running; start one in the experimenter view"};
  if (s.active->session.finished()) throw Reject{"conflict", type + ": the session is finished"};
  if (s.active->suspended) throw Reject{"conflict", "The session is paused; please wait."};
  const ex::Question& q = s.active->session.question();
  const std::int64_t trial = f.integer("trial", 0, 1 << 30);
  if (trial != q.trial)
    throw Reject{"conflict", type + ": trial " + std::to_string(trial) + " is not the current trial (" + std::to_string(q.trial) +
                                 "); ask experiment.current"};
  return q;
}

void show_stimulus(State& s, const std::string& document_json_text) {
  std::lock_guard lock(s.feel_mutex);
  device_to_presenter(s);  // a participant's stimulus takes the device back from the 2-D pad
  s.presenter->show(document_json_text);
}

void new_trial(State& s) {
  std::lock_guard lock(s.feel_mutex);
  s.presenter->blank();
  pad_blank(s);
  s.trace.clear();
  s.trace_client = 0;
  s.strokes2d->selected = -1;
}

std::optional<ex::Protocol> chosen_protocol(const State& s, const json& p) {
  if (p.is_string()) {
    std::optional<ex::Protocol> found;  // the last file of that name, as the list shows them
    for (auto& sh : shipped_protocols(s))
      if (sh.protocol.name == p.get_ref<const std::string&>()) found = std::move(sh.protocol);
    if (found) return found;
    throw Reject{"not_found",
                 "experiment.start: protocol " + clipped(p.get<std::string>()) + " is not one of the studio's protocols"};
  }
  if (p.is_object()) {
    if (p.contains("device") && p["device"].is_string())
      require_builtin_device(p["device"].get<std::string>(), "experiment.start: protocol.device must be a built-in device");
    return ex::parse_protocol(p.dump(), "protocol");
  }
  throw Reject{"bad_message", std::string("experiment.start: protocol must be a name or an object, got ") + p.type_name()};
}

// A scratch folder removed with everything in it when the scope ends.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    std::string t = (std::filesystem::temp_directory_path() / "texel-studio-XXXXXX").string();
    if (!mkdtemp(t.data())) throw IoError("cannot create a temporary folder for the export");
    path = t;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  if (!in && !in.eof()) throw IoError(p.filename().string() + ": cannot read the exported file");
  return os.str();
}

ojson file_json(const std::string& name, const char* mime, const std::string& data) {
  return ojson{{"name", name}, {"mime", mime}, {"bytes", data.size()}, {"data_base64", base64_encode(data)}};
}

std::optional<std::int64_t> session_field(State& s, const Fields& f, const std::string& type, bool required) {
  if (!required && !f.has("session")) return std::nullopt;
  const std::int64_t id = f.integer("session", 1, std::int64_t{1} << 52);
  try {
    (void)the_store(s).session(id);
  } catch (const InvalidArgument&) {
    throw Reject{"not_found", type + ": there is no session " + std::to_string(id)};
  }
  return id;
}

}  // namespace

void on_experiment_list(State& s, Client& c, const Job& job) {
  ojson r = reply("experiment.list", job.id);
  r["protocols"] = ojson::array();
  for (const auto& sh : shipped_protocols(s))
    r["protocols"].push_back({{"name", sh.protocol.name},
                              {"file", sh.file},
                              {"study", sh.protocol.study},
                              {"title", sh.protocol.title},
                              {"description", sh.protocol.description},
                              {"trials_planned", sh.protocol.planned_trials()}});
  r["sessions"] = ojson::array();
  for (const auto& i : the_store(s).sessions()) {
    ojson j = ojson::parse(ex::to_json(i));
    if (s.active && s.active->info.id == i.id) j["state"] = ex::to_string(ex::session_state(i, true, s.active->suspended));
    r["sessions"].push_back(std::move(j));
  }
  r["active"] = s.active ? session_json(s) : ojson(nullptr);
  send(c, r);
}

// Every station's progress and shipping lag (a PostgreSQL store; an SQLite
// one answers multi_station false).
void on_experiment_stations(State& s, Client& c, const Job& job) {
  ojson r = reply("experiment.stations", job.id);
  const ojson v = ojson::parse(ex::stations_json(the_store(s)));
  for (auto it = v.begin(); it != v.end(); ++it) r[it.key()] = it.value();
  send(c, r);
}

void on_experiment_start(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const json& p = f.raw("protocol");
  ex::OpenOptions o;
  o.participant = f.string("participant", 32);
  o.resume = f.boolean("resume", false);
  if (f.has("simulate")) o.simulate = f.string("simulate", max_name_chars);
  const std::optional<ex::Protocol> protocol = chosen_protocol(s, p);
  if (s.active && !s.active->session.finished()) {
    if (s.active->info.participant != o.participant || s.active->info.protocol != protocol->name || !o.resume)
      throw Reject{"conflict", "experiment.start: session " + std::to_string(s.active->info.id) + " (participant " +
                                   s.active->info.participant + ", " + s.active->info.protocol +
                                   ") is running; suspend it first"};
  } else {
    s.active.reset();
    ex::Store& st = the_store(s);
    const bool unfinished = st.unfinished_session(o.participant, protocol->name).has_value();
    if (unfinished && !o.resume)
      throw Reject{"conflict", "experiment.start: participant " + clipped(o.participant) + " has an unfinished " +
                                   protocol->name + " session; resume it instead of starting a new one"};
    if (!unfinished && o.resume)
      throw Reject{"not_found", "experiment.start: participant " + clipped(o.participant) + " has no unfinished " +
                                    protocol->name + " session to resume"};
    {
      // The presentation follows the protocol's device: a study on an
      // actuator array re-opens the output with its channels, before anything
      // is stored (a device that cannot is refused here).
      std::lock_guard lock(s.feel_mutex);
      presenter_channels(s, ex::presentation_channels(*protocol), "experiment.start: protocol " + protocol->name);
    }
    try {
      s.active.emplace(ex::open_session(st, *protocol, o));
    } catch (const InvalidArgument&) {
      throw;
    } catch (const FormatError&) {
      throw;
    } catch (const IoError&) {
      throw;
    } catch (const Error& e) {  // another process is writing this session
      throw Reject{"conflict", std::string("experiment.start: ") + e.what()};
    }
    new_trial(s);
    preload_surfaces(s);
  }
  ojson r = reply("experiment.started", job.id);
  r["session"] = session_json(s);
  r["progress"] = progress_json(s);
  r["resumed"] = o.resume;
  send(c, r);
  tell_everyone(s, c);
}

void on_experiment_current(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const bool reload = f.boolean("reload", false);
  if (f.boolean("screen", false)) c.participant_screen = true;
  send(c, current_state(s, job.id, c.participant_screen, reload));
  // Under on_reload "restart_trial" the reload started the trial again: other screens get its new token.
  if (reload && s.active && ex::reload_rule(s.active->session.protocol()) == ex::ReloadRule::restart_trial) tell_everyone(s, c);
}

void on_experiment_select(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const ex::Question& q = current_question(s, f, job.type);
  if (q.stimuli.empty()) throw Reject{"invalid", "experiment.select: this question has no stimuli"};
  const auto i = static_cast<std::size_t>(f.integer("stimulus", 0, static_cast<std::int64_t>(q.stimuli.size()) - 1));
  ojson r = reply("experiment.selected", job.id);
  r["trial"] = q.trial;
  r["stimulus"] = i;
  r["label"] = q.stimuli[i].label;
  if (q.surfaces.empty()) {
    show_stimulus(s, q.stimuli[i].document_json);
    send(c, r);
    return;
  }
  // A 2-D interval: the participant's page strokes it (experiment.stroke). Leaving an interval
  // stroked along another line brings one plain reminder (about the stroke, nothing of the trial).
  Strokes2DState& st = strokes_of(s);
  auto map = surface_map(st, q.surfaces[i]);  // before the device is taken
  if (st.selected >= 0 && static_cast<std::size_t>(st.selected) != i) {
    const auto k = static_cast<std::size_t>(st.selected);
    const std::string& was = q.stimuli[k].label;
    if (auto it = st.recorders.find(was); it != st.recorders.end()) {
      it->second.add(st.last_t_s, 0.0, 0.0, false);  // its stroke in progress ends here
      const ex::IntervalStrokes last = it->second.summary(was, q.surfaces[k].direction_deg);
      if (last.strokes > 0 && !last.compliant)
        r["reminder"] = "You stroked " + stimulus_words(was) +
                        " along another line than its own: " + ex::direction_words(q.surfaces[k].direction_deg) + ".";
    }
  }
  st.selected = static_cast<int>(i);
  st.recorders.try_emplace(q.stimuli[i].label, stroke_rules);
  {
    std::lock_guard lock(s.feel_mutex);
    pad_show(s, std::move(map));
  }
  r["stroke_deg"] = ex::line_direction(q.surfaces[i].direction_deg);
  r["stroke_words"] = ex::direction_words(q.surfaces[i].direction_deg);
  send(c, r);
}

void on_experiment_preview(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const ex::Question& q = current_question(s, f, job.type);
  if (q.sliders.size() != 2) throw Reject{"invalid", "experiment.preview: this question has no sliders"};
  const double sp = f.number("slider_p", q.sliders[0].min, q.sliders[0].max);
  const double si = f.number("slider_i", q.sliders[1].min, q.sliders[1].max);
  show_stimulus(s, s.active->session.preview_document(sp, si));
  ojson r = reply("experiment.selected", job.id);
  r["trial"] = q.trial;
  r["slider_p"] = sp;
  r["slider_i"] = si;
  send(c, r);
}

void on_experiment_answer(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::int64_t trial = f.integer("trial", 0, 1 << 30);
  ex::Response response;
  std::string token;
  if (f.boolean("simulated", false)) {
    // The experimenter's simulated participant answers the question in force.
    (void)current_question(s, f, job.type);
    if (s.active->simulate.empty())
      throw Reject{"invalid", "experiment.answer: simulated answers need a session started with 'simulate'"};
    response = ex::simulated_participant(*s.active).respond(s.active->session);
    token = ex::hand_out(*s.active).token;
  } else {
    if (!f.has("token"))
      throw Reject{"bad_message", "experiment.answer: a response needs the question's token (handout.token); reload the page"};
    token = f.string("token", 128);
    response = ex::Response::from_json(f.object("response").dump());
    // The server's clock (per token) times the trial, not the page's (a reload restarts a page's clock).
    response.rt_ms = ex::missing;
    response.shown_at.clear();
    response.answered_at.clear();
  }
  (void)trial;  // the token names the trial; `trial` stays for older clients' messages
  if (!f.boolean("simulated", false)) {
    // Strokes are the studio's record of the participant's page (as a 2-D display's presenter records
    // them), never the page's claim; those of the question in force (a stale token is refused below).
    response.strokes.clear();
    if (s.active && !s.active->session.finished() && !s.active->session.question().surfaces.empty())
      response.strokes = stroke_summaries(strokes_of(s), s.active->session.question());
  }
  if (!f.boolean("simulated", false)) {
    // The finger that explored is the studio's record of the pointer (feel.move, on the page's own
    // clock), never the page's claim: the library measures it by the one rule (finger_trace.hpp),
    // stores it with the trial and flags a trace that cannot be a hand's.
    response.swipe_mean_speed_mm_s.reset();
    response.swipe_sd_speed_mm_s.reset();
    response.directional_proportion.reset();
    response.swipe_flag.clear();
    std::lock_guard lock(s.feel_mutex);
    if (!s.trace.empty()) {
      response.trace.source = ex::TraceSource::pointer;
      response.trace.mode = ex::PresentationMode::host_streams;
      response.trace.samples = s.trace;
    }
  }
  try {
    // The token rule (docs/studio.md): committed before the next question goes out, or refused.
    (void)ex::record(the_store(s), s.active ? &*s.active : nullptr, token, std::move(response));
  } catch (const ex::AnswerRefused& e) {
    ojson r = reply("error", job.id);
    r["code"] = "conflict";
    r["message"] = e.what();
    r["reason"] = std::string(ex::to_string(e.reason()));
    send(c, r);
    return;
  }
  new_trial(s);
  send(c, current_state(s, job.id, /*screen=*/true));  // the answering screen (or simulation) sees the next question now
  tell_everyone(s, c);
}

void on_experiment_stop(State& s, Client& c, const Job& job) {
  s.active.reset();
  if (s.strokes2d->maps) s.strokes2d->maps->stop();  // its preload ends (at most the bitmap being rendered)
  new_trial(s);
  send(c, reply("experiment.idle", job.id));
  tell_everyone(s, c);
}

void on_experiment_suspend(State& s, Client& c, const Job& job) {
  if (!s.active || s.active->session.finished())
    throw Reject{"not_found", "experiment.suspend: no session is running; nothing to pause"};
  ex::suspend(*s.active);
  {
    std::lock_guard lock(s.feel_mutex);
    s.presenter->blank();  // nothing to feel while paused
    pad_blank(s);
  }
  send(c, current_state(s, job.id, c.participant_screen));
  tell_everyone(s, c);
}

void on_experiment_resume(State& s, Client& c, const Job& job) {
  if (!s.active) throw Reject{"not_found", "experiment.resume: no session is running; start or resume one first"};
  ex::resume(*s.active);
  send(c, current_state(s, job.id, c.participant_screen));
  tell_everyone(s, c);
}

// The participant's finger on a 2-D question's surface (the page): samples
// [t_ms, x_mm, y_mm, touch], t_ms on the page's clock. Only for the token's
// trial and the interval playing, else refused (nothing recorded).
void on_experiment_stroke(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const ex::Question& q = current_question(s, f, job.type);
  if (q.surfaces.empty()) throw Reject{"invalid", "experiment.stroke: this question is not stroked on a 2-D surface"};
  const std::string token = f.string("token", 128);
  try {
    ex::check_token(the_store(s), &*s.active, token);
  } catch (const ex::AnswerRefused& e) {
    throw Reject{"conflict", std::string("experiment.stroke: ") + e.what()};
  }
  Strokes2DState& st = strokes_of(s);
  const std::int64_t stimulus = f.integer("stimulus", 0, static_cast<std::int64_t>(q.stimuli.size()) - 1);
  if (stimulus != st.selected)
    throw Reject{"conflict", "experiment.stroke: stimulus " + std::to_string(stimulus) +
                                 " is not the one playing; select it first (experiment.select)"};
  const json& samples = f.raw("samples");
  if (!samples.is_array() || samples.size() > max_stroke_samples)
    throw Reject{"bad_message", "experiment.stroke: samples must be an array of at most " + std::to_string(max_stroke_samples) +
                                    " [t_ms, x_mm, y_mm, touch] entries"};
  struct Sample {
    double t_ms, x, y;
    bool touch;
  };
  std::vector<Sample> parsed;
  parsed.reserve(samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const json& e = samples[k];
    const std::string where = "experiment.stroke: samples[" + std::to_string(k) + "]";
    if (!e.is_array() || e.size() != 4)
      throw Reject{"bad_message", where + " must be [t_ms, x_mm, y_mm, touch], got " + clipped(e.dump())};
    for (std::size_t n = 0; n < 3; ++n)
      if (!e[n].is_number() || !std::isfinite(e[n].get<double>()))
        throw Reject{"bad_message", where + "[" + std::to_string(n) + "] must be a finite number, got " + clipped(e[n].dump())};
    const double t_ms = e[0].get<double>(), x = e[1].get<double>(), y = e[2].get<double>();
    if (t_ms < 0 || t_ms > 1e12 || std::abs(x) > max_abs_mm || std::abs(y) > max_abs_mm)
      throw Reject{"invalid", where + " is out of range; allowed: t_ms 0 … 1e12, |x_mm|, |y_mm| <= " + json(max_abs_mm).dump()};
    if (!e[3].is_boolean()) throw Reject{"bad_message", where + "[3] (touch) must be true or false, got " + clipped(e[3].dump())};
    parsed.push_back({t_ms, x, y, e[3].get<bool>()});
  }
  ex::StrokeRecorder& rec = st.recorders.at(q.stimuli[static_cast<std::size_t>(stimulus)].label);
  if (st.page != c.id || (!parsed.empty() && parsed.front().t_ms < st.last_t_s * 1000.0 - 1000.0)) {
    // Another page (or this one reloaded): its own clock. The stroke in progress ends.
    rec.add(st.last_t_s, 0.0, 0.0, false);
    st.timeline = ReportTimeline{};
    st.page = c.id;
    st.last_t_s = parsed.empty() ? 0.0 : parsed.front().t_ms / 1000.0;
  }
  std::size_t played = 0;
  {
    std::lock_guard lock(s.feel_mutex);
    for (const Sample& p : parsed) {
      // Never backwards: the timeline reads a step back as its clock's wrap.
      const double t_s = std::max(p.t_ms / 1000.0, st.last_t_s);
      rec.add(t_s, p.x, p.y, p.touch);
      st.last_t_s = t_s;
      // The page's clock placed on the player's (as a display's reports): due a little after arrival.
      const auto t_us = static_cast<std::uint32_t>(static_cast<std::uint64_t>(std::llround(t_s * 1e6)) & 0xffffffffu);
      const double t = st.timeline.place(t_us, pad_time_s(s) + page_lead_s);
      if (pad_push(s, c.id, t, p.x, p.y, p.touch)) ++played;
    }
  }
  ojson r = reply("experiment.stroked", job.id);
  r["trial"] = q.trial;
  r["stimulus"] = stimulus;
  r["samples"] = parsed.size();
  r["played"] = played;
  send(c, r);
}

}  // namespace texel::studio::detail

// ------------------------------------------------------- experimenter side

namespace texel::studio::detail {

void on_experiment_trials(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::int64_t id = *session_field(s, f, job.type, true);
  ojson r = reply("experiment.trials", job.id);
  r["session"] = s.active && s.active->info.id == id ? session_json(s) : ojson::parse(ex::to_json(the_store(s).session(id)));
  r["rows"] = ojson::array();
  for (const auto& row : the_store(s).rows(id)) r["rows"].push_back(ojson::parse(ex::row_json(row)));
  send(c, r);
}

void on_experiment_export(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::string as = f.string("as", 16);
  const std::optional<std::int64_t> session = session_field(s, f, job.type, false);
  const auto rows = the_store(s).rows(session);
  const std::string stem = session ? "session-" + std::to_string(*session) : "trials";
  ojson r = reply("experiment.exported", job.id);
  r["as"] = as;
  r["trials"] = rows.size();
  r["files"] = ojson::array();
  if (as == "csv") {
    r["files"].push_back(file_json(stem + ".csv", "text/csv", ex::trials_csv(rows)));
  } else if (as == "mat") {
    const TempDir dir;
    const auto path = dir.path / (stem + ".mat");
    texel::mat::write_mat(path.string(), ex::trials_mat_variables(rows));
    r["files"].push_back(file_json(path.filename().string(), "application/x-matlab-data", read_bytes(path)));
  } else if (as == "figures") {
    if (rows.empty()) throw Reject{"invalid", "experiment.export: there are no answered trials to draw"};
    const TempDir dir;
    ex::AnalysisOptions o;
    o.out_dir = dir.path.string();
    o.format = ex::FigureFormat::png;
    const ex::AnalysisReport report = ex::analyze(rows, o);
    for (const auto& fig : report.figures) {
      const std::filesystem::path p(fig);
      r["files"].push_back(file_json(p.filename().string(), "image/png", read_bytes(p)));
    }
    r["summary"] = report.text;
  } else {
    throw Reject{"invalid", "experiment.export: as is " + clipped(as) + "; allowed: csv, mat, figures"};
  }
  send(c, r);
}

void on_experiment_protocol(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::string name = f.string("name", max_name_chars);
  std::optional<std::string> file;  // the last file of that name, as the list shows them
  for (const auto& sh : shipped_protocols(s))
    if (sh.protocol.name == name) file = sh.file;
  if (!file) throw Reject{"not_found", "experiment.protocol: " + clipped(name) + " is not one of the studio's protocols"};
  ojson r = reply("experiment.protocol", job.id);
  r["file"] = *file;
  r["protocol"] = ojson::parse(read_bytes(std::filesystem::path(s.options.protocols_dir) / *file));
  send(c, r);
}

void on_experiment_validate(State& s, Client& c, const Job& job) {
  const Fields f(job.msg, job.type);
  const std::optional<ex::Protocol> p = chosen_protocol(s, f.object("protocol"));
  ojson r = reply("experiment.validated", job.id);
  r["name"] = p->name;
  r["study"] = p->study;
  r["trials_planned"] = p->planned_trials();
  send(c, r);
}

}  // namespace texel::studio::detail
