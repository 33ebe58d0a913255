// Reading the PostgreSQL store (store_pg.hpp: pg::Reader, docs/session-store.md
// "Many stations"): sessions, trials with their events and finger traces,
// trial rows and the stations' progress, through a role's rights (status,
// export, analyze).
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "store_pg_parts.hpp"
#include "texel/error.hpp"
#include "texel/experiment/finger_trace.hpp"
#include "texel/experiment/records.hpp"

namespace texel::experiment::pg {
namespace {

constexpr const char* server_session_columns =
    "SELECT s.id, s.participant, s.protocol, s.study, s.protocol_json, s.seed, s.simulate, "
    "CASE WHEN c.session_uuid IS NULL THEN 'running' ELSE 'finished' END, s.created_at, "
    "greatest(s.created_at, (SELECT max(t.stored_at) FROM texel.trials t WHERE t.station = s.station AND t.session_uuid = "
    "s.uuid), c.completed_at), "
    "(SELECT count(*) FROM texel.trials t WHERE t.station = s.station AND t.session_uuid = s.uuid), s.trials_planned "
    "FROM texel.sessions s LEFT JOIN texel.completions c ON c.station = s.station AND c.session_uuid = s.uuid ";

class ReaderImpl final : public Reader {
 public:
  explicit ReaderImpl(const std::string& db) : t_(parse_target(db)) {
    ConnectFailure f;
    c_ = connect(t_, f);
    if (!c_) throw IoError("cannot connect to " + t_.label + ": " + f.why);
    try {
      check_version(c_, t_.label);
    } catch (...) {
      libpq().PQfinish(c_);
      throw;
    }
  }
  ~ReaderImpl() override { libpq().PQfinish(c_); }
  ReaderImpl(const ReaderImpl&) = delete;
  ReaderImpl& operator=(const ReaderImpl&) = delete;

  [[nodiscard]] const std::string& label() const override { return t_.label; }
  [[nodiscard]] int schema_version() const override { return current_server_schema; }

  [[nodiscard]] std::vector<SessionInfo> sessions() const override {
    Result r = query(std::string(server_session_columns) + "ORDER BY s.id", {}, "listing sessions");
    std::vector<SessionInfo> out;
    for (int i = 0; i < r.rows(); ++i) {
      SessionInfo s;
      s.id = r.i64(i, 0);
      s.participant = r.text(i, 1);
      s.protocol = r.text(i, 2);
      s.study = r.text(i, 3);
      s.protocol_json = r.text(i, 4);
      s.seed = std::stoull(r.text(i, 5));
      s.simulate = r.text(i, 6);
      s.status = r.text(i, 7);
      s.created_at = r.text(i, 8);
      s.updated_at = r.text(i, 9);
      s.trials_done = static_cast<int>(r.i64(i, 10));
      s.trials_planned = static_cast<int>(r.i64(i, 11));
      out.push_back(std::move(s));
    }
    return out;
  }
  [[nodiscard]] std::vector<std::string> participants() const override {
    Result r = query("SELECT DISTINCT participant COLLATE \"C\" FROM texel.sessions ORDER BY 1", {}, "listing participants");
    std::vector<std::string> out;
    for (int i = 0; i < r.rows(); ++i) out.push_back(r.text(i, 0));
    return out;
  }
  [[nodiscard]] std::vector<StoredTrial> trials(std::int64_t id) const override {
    const std::string op = "reading the trials of session " + std::to_string(id);
    // One snapshot for trials and events.
    (void)query("BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY", {}, op);
    struct End {
      PGconn* c;
      ~End() { libpq().PQclear(libpq().PQexec(c, "COMMIT")); }
    } end{c_};
    Result t = query(
        "SELECT t.trial, t.question_json, t.response_json, t.state_json, t.row_json FROM texel.trials t JOIN texel.sessions s "
        "ON s.station = t.station AND s.uuid = t.session_uuid WHERE s.id = $1 ORDER BY t.trial",
        {std::to_string(id)}, op);
    std::vector<StoredTrial> out;
    for (int i = 0; i < t.rows(); ++i) {
      StoredTrial st;
      st.trial = static_cast<int>(t.i64(i, 0));
      st.question_json = t.text(i, 1);
      st.response_json = t.text(i, 2);
      st.state_json = t.text(i, 3);
      st.row = row_from_json(t.text(i, 4), t_.label + ": session " + std::to_string(id) + " trial " + std::to_string(st.trial));
      out.push_back(std::move(st));
    }
    Result e = query(
        "SELECT e.trial, e.t_s, e.kind, e.detail, e.at FROM texel.events e JOIN texel.sessions s ON s.station = e.station AND "
        "s.uuid = e.session_uuid WHERE s.id = $1 ORDER BY e.trial, e.seq",
        {std::to_string(id)}, op);
    for (int i = 0; i < e.rows(); ++i) {
      const auto trial = static_cast<std::size_t>(e.i64(i, 0));
      if (trial >= out.size())
        throw FormatError(t_.label + ": session " + std::to_string(id) + " has events for a missing trial " +
                          std::to_string(trial));
      out[trial].events.push_back(
          TrialEvent{std::strtod(e.text(i, 1).c_str(), nullptr), e.text(i, 2), e.text(i, 3), e.text(i, 4)});
    }
    Result f = query(
        "SELECT f.trial, f.source, f.mode, f.trace FROM texel.finger_traces f JOIN texel.sessions s ON s.station = f.station "
        "AND s.uuid = f.session_uuid WHERE s.id = $1 ORDER BY f.trial",
        {std::to_string(id)}, op);
    for (int i = 0; i < f.rows(); ++i) {
      const auto trial = static_cast<std::size_t>(f.i64(i, 0));
      const std::string where = t_.label + ": session " + std::to_string(id) + " trial " + std::to_string(trial);
      if (trial >= out.size()) throw FormatError(where + ": a finger trace for a missing trial");
      FingerTrace& ft = out[trial].trace;
      ft.source = parse_trace_source(f.text(i, 1));
      if (!f.text(i, 2).empty()) ft.mode = parse_presentation_mode(f.text(i, 2));
      ft.samples = parse_trace_samples(f.text(i, 3), where);
    }
    return out;
  }
  [[nodiscard]] std::string stations() const override {
    std::lock_guard<std::mutex> hold(mu_);
    return station_rows(c_, t_.label);
  }
  [[nodiscard]] std::vector<TrialRow> rows(std::optional<std::int64_t> id) const override {
    std::string sql =
        "SELECT s.id, t.trial, t.row_json, s.participant, s.protocol, s.study FROM texel.trials t JOIN texel.sessions s ON "
        "s.station = t.station AND s.uuid = t.session_uuid ";
    std::vector<std::string> params;
    if (id) {
      sql += "WHERE s.id = $1 ";
      params.push_back(std::to_string(*id));
    }
    sql += "ORDER BY s.id, t.trial";
    Result r = query(sql, params, "reading trial rows");
    std::vector<TrialRow> out;
    out.reserve(static_cast<std::size_t>(r.rows()));
    for (int i = 0; i < r.rows(); ++i) {
      TrialRow row = row_from_json(r.text(i, 2), t_.label + ": session " + r.text(i, 0) + " trial " + r.text(i, 1));
      row.session_id = r.i64(i, 0);
      row.trial = static_cast<int>(r.i64(i, 1));
      row.participant = r.text(i, 3);
      row.protocol = r.text(i, 4);
      row.study = r.text(i, 5);
      out.push_back(std::move(row));
    }
    return out;
  }

 private:
  Result query(const std::string& sql, const std::vector<std::string>& params, const std::string& op) const {
    std::lock_guard<std::mutex> hold(mu_);
    Result r = run(c_, sql, params);
    if (!r.ok()) {
      if (libpq().PQstatus(c_) != CONNECTION_OK)
        throw IoError(t_.label + ": " + op + " failed: the server went away (" + r.error() + ")");
      throw IoError(t_.label + ": " + op + " failed: " + r.error());
    }
    return r;
  }
  Target t_;
  PGconn* c_ = nullptr;
  mutable std::mutex mu_;
};

}  // namespace

std::shared_ptr<Reader> open_reader(const std::string& db) { return std::make_shared<ReaderImpl>(db); }

}  // namespace texel::experiment::pg
