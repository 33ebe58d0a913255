// texel experiment run|cohort|list|status|export|analyze — the terminal front
// door to the experiment engine (docs/experiments.md). It parses, drives the
// library's Session one question at a time (the terminal runner that asks a
// person is cmd_experiment_terminal.cpp), stores every answer before the next
// question, and formats; the studies' logic lives in libtexel_experiment.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>

#include "commands.hpp"
#include "common.hpp"
#include "experiment_terminal.hpp"
#include "option_flags.hpp"
#include "texel/detail/format.hpp"
#include "texel/error.hpp"
#include "texel/experiment/analysis.hpp"
#include "texel/experiment/export_mat.hpp"
#include "texel/experiment/presenter.hpp"
#include "texel/experiment/protocol.hpp"
#include "texel/experiment/records.hpp"
#include "texel/experiment/runner.hpp"
#include "texel/experiment/session.hpp"
#include "texel/experiment/simulate.hpp"
#include "texel/experiment/store.hpp"
#include "texel/experiment/table.hpp"
#include "texel/io.hpp"
#include "texel/matfile.hpp"

namespace texel::cli {
namespace {

namespace ex = texel::experiment;
using nlohmann::json;
using nlohmann::ordered_json;

// --------------------------------------------------------------------- run

struct RunArgs {
  std::string protocol;
  std::string participant;
  std::string db;
  std::string journal;  // a station's local journal (--db names a PostgreSQL server)
  std::optional<std::string> simulate;
  double pace = 0.0;
  bool resume = false;
  std::string backend = "null";
  std::string audio_device;
  std::string response = "limit";
  std::optional<std::string> finger;  // serial:PATH — the participant strokes a 2-D display
  std::optional<std::string> mode;    // display-plays | host-streams | passive (default: the display's own)
  double direction_tolerance_deg = ex::StrokeRules{}.tolerance_deg;
  bool json = false;
  bool quiet = false;
  std::optional<std::string> monitor;
};

std::string count_text(int n) { return n >= 0 ? std::to_string(n) : std::string("adaptive"); }

// A word for a POSIX shell: as is when it is plain, else in single quotes.
std::string shell_word(const std::string& w) {
  const bool plain = !w.empty() && std::all_of(w.begin(), w.end(), [](unsigned char c) {
    return std::isalnum(c) || std::strchr("@%+=:,./_-", c) != nullptr;
  });
  if (plain) return w;
  std::string q = "'";
  for (const char c : w) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The command that continues this session: every option that decides where
// the stimuli go, where the finger comes from, how they are presented and
// where the answers are stored (a resume on another backend would run the
// rest of the study on other hardware, silently).
std::string resume_command(const RunArgs& a) {
  std::string c = "texel experiment run " + shell_word(a.protocol) + " --participant " + shell_word(a.participant) + " --db " +
                  shell_word(a.db);
  if (!a.journal.empty()) c += " --journal " + shell_word(a.journal);
  c += " --backend " + shell_word(a.backend);
  if (!a.audio_device.empty()) c += " --audio-device " + shell_word(a.audio_device);
  if (a.finger) c += " --finger " + shell_word(*a.finger);
  if (a.finger && a.direction_tolerance_deg != ex::StrokeRules{}.tolerance_deg)
    c += " --direction-tolerance " + detail::num(a.direction_tolerance_deg);
  if (a.mode) c += " --mode " + shell_word(*a.mode);
  if (a.response != "limit") c += " --response " + shell_word(a.response);
  if (a.pace > 0) c += " --pace " + detail::num(a.pace);
  if (a.monitor) c += " --monitor " + shell_word(*a.monitor);
  return c + " --resume";
}

// A station whose server is not there runs on its journal, and says so.
void warn_if_offline(const ex::Store& store) {
  const ex::ShipStatus s = store.shipping();
  if (!s.connected)
    std::cerr << "texel: " << s.server << " is not reachable (" << s.last_error << "); running on the local journal " << s.journal
              << ": every trial is stored there and shipped when the server is back (texel experiment sync)\n";
}

// At the end of a station's run: a few seconds to ship what is left; what
// is not shipped stays in the journal for the next run or `sync`.
void finish_shipping(ex::Store& store) {
  if (store.sync(5.0)) return;
  const ex::ShipStatus s = store.shipping();
  std::cerr << "texel: " << (s.trials_local - s.trials_shipped) << " trials and " << s.completions_pending
            << " completion records are not on " << s.server << " yet"
            << (s.last_error.empty() ? std::string() : " (" + s.last_error + ")") << "; they are kept in " << s.journal
            << " and shipped by the next run or texel experiment sync\n";
}

// texel experiment sync: where shipping stands, then ship everything now.
void sync_command(const std::string& db, const std::string& journal, double timeout_s, bool as_json) {
  if (!ex::is_postgres(db)) throw InvalidArgument("sync: --db must name a PostgreSQL server (postgresql://… or service=NAME)");
  if (!(timeout_s > 0 && timeout_s <= 3600))
    throw InvalidArgument("--timeout is " + detail::num(timeout_s) + "; allowed: 0 … 3600 s");
  const std::string local = journal.empty() ? ex::default_journal(db) : journal;
  if (!std::filesystem::exists(local)) throw IoError("sync: no journal at " + local + " (nothing was run on this station)");
  ex::Store store = ex::Store::open(db, ex::StoreMode::read_write, ex::StoreOptions{local});
  const ex::ShipStatus before = store.shipping();
  const bool done = store.sync(timeout_s);
  const ex::ShipStatus s = store.shipping();
  if (as_json) {
    ordered_json j = ordered_json::parse(ex::to_json(s));
    j["trials_shipped_before"] = before.trials_shipped;
    j["synced"] = done;
    print_json(j);
  } else {
    std::cout << "station " << s.station << " → " << s.server << " (journal " << s.journal << ")\n"
              << "  trials: " << s.trials_local << " stored locally, " << before.trials_shipped << " on the server before, "
              << s.trials_shipped << " now\n"
              << "  sessions: " << s.sessions_local << ", completion records waiting: " << s.completions_pending << "\n";
    for (const auto& c : s.conflicts) std::cout << "  CONFLICT: " << c << "\n";
  }
  if (!done)
    throw IoError("sync: " + std::to_string(s.trials_local - s.trials_shipped) + " trials are not on " + s.server + " (" +
                  (s.last_error.empty() ? std::string("timed out") : s.last_error) + "); they stay in " + s.journal);
}

void run(const RunArgs& a) {
  if (!(a.pace >= 0 && a.pace <= 3600)) throw InvalidArgument("--pace is " + detail::num(a.pace) + "; allowed: 0 … 3600 s");
  // Everything that can be checked is checked before the database is
  // touched; a database this command created is removed again if the
  // session cannot start, so a failed command leaves nothing behind.
  const ex::Protocol protocol_file = ex::load_protocol(a.protocol);
  if (a.simulate) (void)ex::simulation_observer(protocol_file.observer, *a.simulate);
  ex::PresenterOptions po;
  po.backend = a.backend;
  po.audio_device = a.audio_device;
  po.response_handling = parse_response_handling(a.response, "--response");
  if (a.mode) po.mode = ex::parse_presentation_mode(*a.mode, "--mode");
  po.channels = ex::presentation_channels(protocol_file);  // one per actuator of the protocol's device
  const auto two_d = [](const ex::Block& b) { return b.task == "oddity-2d"; };
  const bool all_2d = std::all_of(protocol_file.blocks.begin(), protocol_file.blocks.end(), two_d);
  if (a.finger && !std::any_of(protocol_file.blocks.begin(), protocol_file.blocks.end(), two_d)) {
    // A 1-D study: the finger from a sensor on a link of its own, streamed to the backend (host-streams).
    po.finger = ex::FingerSource::sensor;
    po.finger_display = *a.finger;
  } else if (a.finger) {
    // The participant strokes a 2-D display: every block must be a 2-D oddity.
    if (a.simulate)
      throw InvalidArgument("--finger: a simulated participant does not stroke a display; give --finger or --simulate");
    if (!all_2d)
      throw InvalidArgument(
          "--finger: the protocol mixes 2-D (oddity-2d) and 1-D blocks; a 2-D display's finger plays "
          "the 2-D blocks only: run them as a protocol of their own");
    po.finger = ex::FingerSource::display;
    po.finger_display = *a.finger;
    po.stroke_rules.tolerance_deg = a.direction_tolerance_deg;
    if (!(a.direction_tolerance_deg >= 0 && a.direction_tolerance_deg <= 90))
      throw InvalidArgument("--direction-tolerance is " + detail::num(a.direction_tolerance_deg) + "; allowed: 0 … 90 degrees");
  }
  ex::Presenter presenter(po);
  // The experimenter's stream: opened before the database, removed again
  // (if this command created it) when the session cannot start.
  Monitor monitor;
  const bool monitor_created = a.monitor && monitor.open(*a.monitor);
  // With a PostgreSQL --db the file this command may create is the journal.
  const std::string local = ex::is_postgres(a.db) ? (a.journal.empty() ? ex::default_journal(a.db) : a.journal) : a.db;
  const bool existed = std::filesystem::exists(local);
  std::optional<ex::Store> opened;
  std::optional<ex::ActiveSession> started;
  try {
    opened.emplace(ex::Store::open(a.db, ex::StoreMode::read_write, ex::StoreOptions{a.journal}));
    ex::OpenOptions oo;
    oo.participant = a.participant;
    oo.resume = a.resume;
    oo.simulate = a.simulate;
    try {
      started.emplace(ex::open_session(*opened, protocol_file, oo));
    } catch (const ex::SessionConflict& e) {  // how to do the other thing, in this command's words
      throw InvalidArgument(std::string(e.what()) + (e.kind() == ex::SessionConflict::Kind::unfinished_exists
                                                         ? " (--resume)"
                                                         : " (start one without --resume)"));
    }
  } catch (const Error&) {
    opened.reset();
    monitor.close();
    if (monitor_created) std::filesystem::remove(*a.monitor);
    if (!existed)
      for (const char* suffix : {"", "-wal", "-shm", "-journal", "-shipping.db", "-shipping.db-wal", "-shipping.db-shm"})
        std::filesystem::remove(local + suffix);
    throw;
  }
  if (opened->is_station()) warn_if_offline(*opened);
  ex::Store& store = *opened;
  ex::ActiveSession& active = *started;
  const ex::Session& session = active.session;
  const ex::Protocol& protocol = session.protocol();
  const ex::SessionInfo& info = active.info;
  const std::string& simulate = active.simulate;
  std::optional<ex::SimulatedParticipant> sim;
  if (!simulate.empty()) sim.emplace(ex::simulated_participant(active));
  // A 2-D display: the session's friction bitmaps render in the background
  // from now on (instructions, practice), not while the participant waits.
  presenter.preload(protocol, session.context());

  experiment_interrupted = false;
  auto old_int = std::signal(SIGINT, on_experiment_signal);
  auto old_term = std::signal(SIGTERM, on_experiment_signal);
  auto old_pipe = std::signal(SIGPIPE, SIG_IGN);  // a monitor FIFO whose reader left ends the stream, not the run
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  const std::string resume_command = cli::resume_command(a);
  monitor.event("start", {{"session", std::to_string(info.id)},
                          {"participant", a.participant},
                          {"protocol", protocol.name},
                          {"study", protocol.study},
                          {"resume", a.resume ? "1" : "0"},
                          {"trials_stored", std::to_string(session.trials_done())},
                          {"trials_planned", count_text(session.trials_planned())},
                          {"simulated", sim ? (simulate.empty() ? std::string("default") : simulate) : std::string()},
                          {"db", a.db}});
  // What this display cannot do for the protocol, before the first trial.
  if (!session.finished())
    for (const std::string& w : presenter.check(session.question())) {
      monitor.event("presentation_warning", {{"mode", std::string(to_string(presenter.mode()))}, {"warning", w}});
      if (!a.quiet) std::cerr << "texel: warning: " << w << "\n";
    }
  monitor.event("audio", {{"backend", presenter.describe()},
                          {"mode", std::string(to_string(presenter.mode()))},
                          {"response", std::string(to_string(po.response_handling))},
                          {"block_ms", detail::fixed(presenter.block_period_s() * 1e3, 3)},
                          {"finger", a.finger ? *a.finger : std::string()},
                          {"direction_tolerance_deg", a.finger ? detail::num(a.direction_tolerance_deg) : std::string()}});
  // Reversals so far per block (a resumed session counts its stored trials).
  std::map<std::string, int> reversals;
  for (const auto& row : store.rows(info.id))
    if (row.reversal) ++reversals[row.block];
  std::uint64_t late_blocks = presenter.stats().underruns;
  // The participant's terminal (no --simulate) shows only what does not
  // depend on the answers or the procedure's state; the rest goes to the
  // monitor. A simulated run has no participant and reports on stderr.
  if (!sim && !a.quiet)
    tell_participant(a.resume ? "Welcome back. The study continues where it stopped."
                              : "Welcome, and thank you for taking part. Each trial explains what to do; type 'h' for help.");
  if (sim && !a.quiet)
    std::cerr << (a.resume ? "resuming" : "starting") << " session " << info.id << ": " << protocol.name << " for "
              << a.participant
              << (sim ? " (simulated: " + (simulate.empty() ? std::string("default") : simulate) + ")" : std::string()) << ", "
              << session.trials_done() << " trials stored, backend " << presenter.describe() << "\n";

  const int planned = session.trials_planned();
  while (!session.finished() && !experiment_interrupted) {
    const ex::Question& q = session.question();
    ex::Response r;
    if (sim) {
      report_question(monitor, session);
      // Present as a participant would: each stimulus in turn (the pace
      // shared among them), then answer.
      presenter.prepare(q);
      for (std::size_t k = 0; k < q.stimuli.size(); ++k) {
        presenter.show(q, k);
        wait_pumping(&presenter, a.pace / static_cast<double>(std::max<std::size_t>(1, q.stimuli.size())));
      }
      if (q.stimuli.empty()) wait_pumping(&presenter, a.pace);
      if (experiment_interrupted) break;
      r = sim->respond(session);
      r.shown_at = r.answered_at = ex::utc_timestamp();
      presenter.blank();
      r.trace = presenter.take_trace();  // the finger that explored (a display's, while the simulated observer answers)
    } else {
      StopReason stop = StopReason::none;
      auto answer = ask_terminal(session, &presenter, monitor, stop);
      if (!answer) break;  // 'q', end of input or Ctrl-C: everything answered is stored
      r = std::move(*answer);
    }
    const ex::TrialTruth truth = session.truth();
    ex::StoredTrial t;
    try {
      t = ex::record(store, active, r);  // committed (fsync) before the next question appears
    } catch (const InvalidArgument& e) {
      if (sim) throw;
      monitor.event("refused", {{"trial_number", std::to_string(q.trial + 1)}, {"reason", e.what()}});
      tell_participant("  That is not a valid answer; the trial starts again.");
      continue;
    }
    presenter.blank();
    if (t.row.reversal) ++reversals[t.row.block];
    monitor.event("result",
                  {{"trial_number", std::to_string(t.trial + 1)},
                   {"block", t.row.block},
                   {"response", t.row.response},
                   {"correct_answer", truth.correct_answer},
                   {"correct", std::isfinite(t.row.correct) ? detail::num(t.row.correct) : std::string()},
                   {"variable", t.row.variable},
                   {"value", std::isfinite(t.row.intensity) ? detail::num(t.row.intensity) : std::string()},
                   {"next_value", std::isfinite(t.row.next_intensity) ? detail::num(t.row.next_intensity) : std::string()},
                   {"reversal", t.row.reversal ? "1" : "0"},
                   {"reversals", std::to_string(reversals[t.row.block])},
                   {"rt_ms", std::isfinite(t.row.rt_ms) ? detail::num(t.row.rt_ms) : std::string()},
                   {"trials_stored", std::to_string(session.trials_done())},
                   {"trials_planned", count_text(planned)}});
    if (const std::uint64_t late = presenter.stats().underruns; late != late_blocks) {
      monitor.event("late_blocks", {{"total", std::to_string(late)}, {"new", std::to_string(late - late_blocks)}});
      late_blocks = late;
    }
    if (!sim && !a.quiet) tell_participant(session.finished() ? "  Answer saved." : "  Answer saved. Next trial.");
    if (sim && tty && !a.quiet)
      std::fprintf(
          stderr, "\rtrial %d%s  block %s  %s   ", session.trials_done(),
          planned > 0 ? ("/" + std::to_string(planned)).c_str() : "", t.row.block.c_str(),
          std::isfinite(t.row.next_intensity) ? (t.row.variable + " → " + detail::num(t.row.next_intensity)).c_str() : "");
  }
  if (sim && tty && !a.quiet) std::fprintf(stderr, "\n");
  presenter.stop();  // the display at rest before a second Ctrl-C could end the process
  std::signal(SIGINT, old_int);
  std::signal(SIGTERM, old_term);
  std::signal(SIGPIPE, old_pipe);
  const bool finished = session.finished();

  const BackendStats s = presenter.stats();
  monitor.event("audio_stats", {{"backend", presenter.describe()},
                                {"blocks", std::to_string(s.blocks)},
                                {"worst_block_ms", detail::fixed(s.worst_block_s * 1e3, 3)},
                                {"late_blocks", std::to_string(s.underruns)},
                                {"stimuli_shown", std::to_string(presenter.shown())}});
  if (finished)
    monitor.event("finish", {{"session", std::to_string(info.id)}, {"trials_stored", std::to_string(session.trials_done())}});
  else
    monitor.event("suspend", {{"session", std::to_string(info.id)},
                              {"trials_stored", std::to_string(session.trials_done())},
                              {"resume", resume_command}});
  ordered_json j;
  j["session"] = info.id;
  j["participant"] = a.participant;
  j["protocol"] = protocol.name;
  j["study"] = protocol.study;
  j["finished"] = finished;
  j["trials"] = session.trials_done();
  j["backend"] = presenter.describe();
  j["response"] = std::string(to_string(po.response_handling));
  j["blocks_processed"] = s.blocks;
  j["worst_block_ms"] = s.worst_block_s * 1e3;
  j["worst_block_fraction"] = presenter.block_period_s() > 0 ? s.worst_block_s / presenter.block_period_s() : 0.0;
  j["mean_block_ms"] = s.blocks ? s.total_block_s / static_cast<double>(s.blocks) * 1e3 : 0.0;
  j["late_blocks"] = s.underruns;
  j["stimuli_shown"] = presenter.shown();
  j["mode"] = std::string(to_string(presenter.mode()));
  if (presenter.mode() == ex::PresentationMode::display_plays) {
    const ex::Presenter::UploadCounts u = presenter.upload_counts();
    j["maps_uploaded"] = u.uploads;
    j["maps_uploaded_at_switch"] = u.at_switch;
    j["upload_s"] = u.seconds;
  }
  if (!a.finger && presenter.mode() != ex::PresentationMode::passive) {
    const ex::Presenter::FingerCounts f = presenter.finger_counts();
    j["finger_reports"] = f.reports;
    j["finger_reports_lost"] = f.lost;
  }
  if (!finished) j["resume"] = resume_command;
  if (a.finger) {
    const ex::Presenter::FingerCounts f = presenter.finger_counts();
    j["finger"] = *a.finger;
    j["finger_reports"] = f.reports;
    j["finger_reports_lost"] = f.lost;
    j["finger_reports_dropped"] = f.dropped;
  }
  if (a.json) {
    print_json(j);
  } else if (!sim && !a.quiet) {
    // The participant's screen: no figures; the experimenter's line last.
    tell_participant(finished ? "\nThe study is complete. Thank you for taking part!"
                              : "\nThe study has stopped here and your answers are saved. Please tell the experimenter.");
    if (!finished) tell_participant("(experimenter: continue with " + resume_command + ")");
  } else if (!a.quiet) {
    std::cout << (finished ? "finished" : "stopped") << " session " << info.id << " (" << protocol.name << ", " << a.participant
              << "): " << session.trials_done() << " trials stored in " << a.db << "\n"
              << "backend " << presenter.describe() << ": " << s.blocks << " blocks, worst "
              << detail::fixed(s.worst_block_s * 1e3, 3) << " ms, late blocks " << s.underruns << "\n";
    if (!finished) std::cout << "resume with: " << resume_command << "\n";
  }
  if (store.is_station()) finish_shipping(store);
  if (!presenter.error().empty()) throw IoError("experiment run: " + presenter.error());
}

// ------------------------------------------------------- list / status / export / analyze

void list_sessions(const std::string& db, bool as_json, const std::optional<std::string>& participant) {
  const ex::Store store = ex::Store::open(db, ex::StoreMode::read_only);
  const auto sessions = store.sessions();
  ordered_json arr = ordered_json::array();
  for (const auto& s : sessions)
    if (!participant || s.participant == *participant) arr.push_back(ordered_json::parse(ex::to_json(s)));
  if (as_json) {
    print_json(arr);
    return;
  }
  std::printf("%-4s %-12s %-20s %-10s %-12s %s\n", "id", "participant", "protocol", "state", "trials", "updated");
  for (const auto& s : arr) {
    const int planned = s["trials_planned"].get<int>();
    const std::string trials = std::to_string(s["trials_done"].get<int>()) + (planned > 0 ? "/" + std::to_string(planned) : "");
    std::printf("%-4lld %-12s %-20s %-10s %-12s %s\n", static_cast<long long>(s["id"].get<std::int64_t>()),
                s["participant"].get<std::string>().c_str(), s["protocol"].get<std::string>().c_str(),
                s["state"].get<std::string>().c_str(), trials.c_str(), s["updated_at"].get<std::string>().c_str());
  }
}

void status(const std::string& db, bool as_json, const std::optional<std::string>& participant) {
  const ex::Store store = ex::Store::open(db, ex::StoreMode::read_only);
  const ordered_json out = ordered_json::parse(ex::status_json(store, db, participant));
  const ordered_json& sessions = out["sessions"];
  if (as_json) {
    print_json(out);
    return;
  }
  std::cout << db << ": schema " << store.schema_version() << ", " << out["participants"].size() << " participants, "
            << sessions.size() << " sessions\n";
  for (const auto& s : sessions) {
    std::cout << "  session " << s["id"] << " " << s["participant"].get<std::string>() << " " << s["protocol"].get<std::string>()
              << " [" << s["state"].get<std::string>() << "] " << s["trials_done"] << " trials\n";
    for (auto it = s["blocks"].begin(); it != s["blocks"].end(); ++it) {
      std::cout << "    " << it.key() << ": " << it.value()["trials"] << " trials";
      if (it.value().contains("current_value"))
        std::cout << ", " << it.value()["variable"].get<std::string>() << " = "
                  << detail::num(it.value()["current_value"].get<double>()) << ", " << it.value()["reversals"] << " reversals"
                  << (it.value()["finished"].get<bool>() ? " (finished)" : "");
      std::cout << "\n";
    }
  }
}

}  // namespace

void register_experiment(CLI::App& app) {
  auto* cmd = app.add_subcommand("experiment", "Run the perceptual studies: protocols, sessions, export, analysis");
  cmd->require_subcommand(1);

  auto a = std::make_shared<RunArgs>();
  auto* run_cmd = cmd->add_subcommand("run", "Run a protocol for a participant (terminal or --simulate), storing every answer");
  run_cmd->add_option("protocol", a->protocol, "Protocol file (.json; examples/protocols/)")->required();
  run_cmd->add_option("--participant", a->participant, "Pseudonymous participant code (1–32 of A–Z a–z 0–9 _ . -)")->required();
  run_cmd
      ->add_option("--db", a->db,
                   "Session database (SQLite; created if missing), or a PostgreSQL server (postgresql://… or service=NAME)")
      ->required();
  run_cmd->add_option("--journal", a->journal,
                      "With a PostgreSQL --db: this station's local journal (SQLite) [~/.local/state/texel/journal-….db]");
  run_cmd->add_option("--simulate", a->simulate,
                      "Answer with a simulated observer: 'default' or key=value pairs, e.g. threshold=6mm, target=4sin, "
                      "target=8dB/-3dB, noise=1dB, seed=3");
  run_cmd->add_option("--pace", a->pace, "Simulated: seconds spent on each trial (demos, kill tests) [0]");
  run_cmd->add_flag("--resume", a->resume, "Continue the participant's unfinished session of this protocol");
  run_cmd->add_option("--backend", a->backend, "Stimulus output: null (no hardware), audio (PortAudio) or serial:PATH [null]");
  run_cmd->add_option("--audio-device", a->audio_device, "PortAudio output: index or name substring [default output]");
  run_cmd->add_option("--finger", a->finger,
                      "Where the participant's finger comes from, serial:PATH. oddity-2d studies: the 2-D display the "
                      "participant strokes (the --backend serial:PATH display, or another). 1-D studies: a sensor on a "
                      "link of its own (a display or strip that reports the finger) while the --backend plays, e.g. a "
                      "sound card's actuators (host-streams)");
  run_cmd->add_option("--mode", a->mode,
                      "How the stimuli reach the finger: display-plays (the display stores each stimulus and plays it "
                      "from its own finger sensor), host-streams (the host streams the drive from the display's reported "
                      "finger) or passive (a simulated sweep, where no finger exists) [the display's own: display-plays "
                      "with map slots and a sensor, host-streams with a sensor only, passive without one]");
  run_cmd->add_option("--direction-tolerance", a->direction_tolerance_deg,
                      "--finger: largest deviation (degrees) of an interval's mean stroke direction from the one asked for [20]");
  run_cmd->add_option("--response", a->response,
                      "The stimuli's display frequency response (the protocol's device profile): limit (never drive "
                      "what the display attenuates by 20 dB or more) or off [limit]");
  run_cmd->add_flag("--json", a->json,
                    "Print the run summary as JSON (with the output's figures: for scripts, not a participant's screen)");
  run_cmd->add_flag("--quiet", a->quiet, "No welcome, end, progress or summary text");
  run_cmd->add_option("--monitor", a->monitor,
                      "The experimenter's stream: one line per event (question, stimulus played, answer, correctness, "
                      "staircase value, reversals, audio, suspend/finish) appended to a file or FIFO, or '-' for stderr; "
                      "the participant's terminal shows none of it (watch it with tail -f PATH)");
  run_cmd->callback([a] { run(*a); });

  struct CohortArgs {
    std::vector<std::string> protocols;
    std::string db;
    int participants = 8;
    std::string prefix = "P";
    std::string simulate = "default";
  };
  auto co = std::make_shared<CohortArgs>();
  auto* cohort_cmd = cmd->add_subcommand("cohort", "Run simulated participants through protocols (demos, planning sample sizes)");
  cohort_cmd->add_option("protocols", co->protocols, "Protocol files")->required();
  cohort_cmd->add_option("--db", co->db, "Session database (created if missing)")->required();
  cohort_cmd->add_option("--participants", co->participants, "Number of simulated participants, 1 … 1000 [8]");
  cohort_cmd->add_option("--prefix", co->prefix, "Participant codes PREFIX01, PREFIX02, … [P]");
  cohort_cmd->add_option("--simulate", co->simulate, "Observer spec, as for run --simulate [default]");
  cohort_cmd->callback([co] {
    if (co->participants < 1 || co->participants > 1000)
      throw InvalidArgument("--participants is " + std::to_string(co->participants) + "; allowed: 1 … 1000");
    std::vector<ex::Protocol> protocols;
    for (const auto& p : co->protocols) protocols.push_back(ex::load_protocol(p));  // all valid before anything is stored
    std::vector<std::string> codes;
    for (int i = 1; i <= co->participants; ++i) {
      char code[48];
      std::snprintf(code, sizeof code, "%s%02d", co->prefix.c_str(), i);
      codes.emplace_back(code);
    }
    ex::Store store = ex::Store::open(co->db, ex::StoreMode::read_write);
    for (const auto& p : protocols) {
      const auto ids = ex::simulate_cohort(store, p, codes, co->simulate);
      std::cerr << p.name << ": " << ids.size() << " simulated sessions in " << co->db << "\n";
    }
    if (store.is_station()) finish_shipping(store);
  });

  struct DbArgs {
    std::string db;
    bool json = false;
    std::optional<std::string> participant;
  };
  auto l = std::make_shared<DbArgs>();
  auto* list_cmd = cmd->add_subcommand("list", "List the sessions in a database");
  list_cmd->add_option("--db", l->db, "Session database")->required();
  list_cmd->add_option("--participant", l->participant, "Only this participant");
  list_cmd->add_flag("--json", l->json, "JSON output");
  list_cmd->callback([l] { list_sessions(l->db, l->json, l->participant); });

  auto st = std::make_shared<DbArgs>();
  auto* status_cmd = cmd->add_subcommand("status", "Progress of every session: trials, blocks, staircase values");
  status_cmd->add_option("--db", st->db, "Session database")->required();
  status_cmd->add_option("--participant", st->participant, "Only this participant");
  status_cmd->add_flag("--json", st->json, "JSON output");
  status_cmd->callback([st] { status(st->db, st->json, st->participant); });

  struct SyncArgs {
    std::string db, journal;
    double timeout = 30.0;
    bool json = false;
  };
  auto sy = std::make_shared<SyncArgs>();
  auto* sync_cmd = cmd->add_subcommand("sync", "A station: show its shipping to the PostgreSQL server and ship everything now");
  sync_cmd->add_option("--db", sy->db, "The PostgreSQL server (postgresql://… or service=NAME)")->required();
  sync_cmd->add_option("--journal", sy->journal, "This station's journal [as experiment run]");
  sync_cmd->add_option("--timeout", sy->timeout, "Seconds to wait for the server [30]");
  sync_cmd->add_flag("--json", sy->json, "JSON output");
  sync_cmd->callback([sy] { sync_command(sy->db, sy->journal, sy->timeout, sy->json); });

  struct ExportArgs {
    std::string db;
    std::string output;
    std::optional<std::int64_t> session;
    std::string mat_version = "5";
  };
  auto e = std::make_shared<ExportArgs>();
  auto* export_cmd =
      cmd->add_subcommand("export", "Export every trial as long-format CSV (one row per trial; docs/experiments.md)");
  export_cmd->add_option("--db", e->db, "Session database")->required();
  export_cmd->add_option("-o,--output", e->output, "Output .csv, or .mat (MATLAB: struct 'trials', one column per field)")
      ->required();
  export_cmd->add_option("--session", e->session, "Only this session id");
  export_cmd->add_option("--mat-version", e->mat_version, "MATLAB file version of a .mat output: 5 (default) or 7.3 (HDF5)")
      ->default_str("5");
  export_cmd->callback([e] {
    const std::string ext = output_extension(e->output);
    if (ext != ".csv" && ext != ".mat") throw InvalidArgument("--output is '" + e->output + "'; allowed: a .csv or .mat file");
    const texel::mat::MatVersion mat_version = texel::mat::parse_mat_version(e->mat_version);
    check_writable(e->output);
    const ex::Store store = ex::Store::open(e->db, ex::StoreMode::read_only);
    if (e->session) (void)store.session(*e->session);
    const auto rows = store.rows(e->session);
    if (ext == ".mat")
      texel::mat::write_mat(e->output, ex::trials_mat_variables(rows), {.version = mat_version});  // atomic
    else
      write_file_atomic(e->output, ex::trials_csv(rows));
    std::cerr << "wrote " << rows.size() << " trials to " << e->output << "\n";
  });

  // The analysis options are the library's (AnalysisOptions, described by visit_options): flags, help and defaults
  // come from there; only the inputs and outputs are this command's own.
  struct AnalyzeArgs {
    std::optional<std::string> db;
    std::optional<std::string> csv;
    std::optional<std::string> out_dir;
    ex::AnalysisOptions options;
    std::unique_ptr<DescribedFlags> flags;
    bool json = false;
  };
  auto an = std::make_shared<AnalyzeArgs>();
  auto* analyze_cmd = cmd->add_subcommand("analyze", "Per-study summaries and figures (staircases, matches, ratings, ANOVA)");
  analyze_cmd->add_option("--db", an->db, "Session database");
  analyze_cmd->add_option("--csv", an->csv, "…or a CSV written by 'texel experiment export'");
  analyze_cmd->add_option("-o,--out", an->out_dir, "Folder for the figures (created if missing)");
  an->flags = std::make_unique<DescribedFlags>(analyze_cmd, an->options);
  analyze_cmd->add_flag("--json", an->json, "Print the summary as JSON");
  analyze_cmd->callback([an] {
    if (an->db.has_value() == an->csv.has_value()) throw InvalidArgument("analyze: give exactly one of --db FILE or --csv FILE");
    an->flags->apply();
    std::vector<ex::TrialRow> rows;
    if (an->db)
      rows = ex::Store::open(*an->db, ex::StoreMode::read_only).rows();
    else
      rows = ex::parse_trials_csv(read_file(*an->csv), *an->csv);
    ex::AnalysisOptions o = an->options;
    if (an->out_dir) o.out_dir = *an->out_dir;  // created by analyze(), and removed again if it fails
    const ex::AnalysisReport report = ex::analyze(rows, o);
    if (an->json)
      print_json(ordered_json::parse(report.summary));
    else
      std::cout << report.text;
    for (const auto& f : report.figures) std::cerr << "wrote " << f << "\n";
    for (const auto& f : report.tables) std::cerr << "wrote " << f << "\n";
  });
}

}  // namespace texel::cli
