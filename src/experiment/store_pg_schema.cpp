// The PostgreSQL store's server schema (store_pg.hpp, docs/session-store.md
// "Many stations"): its numbered migrations — the tables, the study-wide
// lease functions, the stations' and analysts' rights — and texel store init
// (init_postgres), which takes the schema to this build's version and
// creates the roles.
#include <algorithm>
#include <array>
#include <cctype>
#include <string>
#include <vector>

#include "store_pg_parts.hpp"
#include "texel/error.hpp"
#include "texel/experiment/store.hpp"

namespace texel::experiment {
namespace pg {
namespace {

// Server migrations, numbered like the SQLite ones: migrations[v] takes the
// texel schema from version v to v + 1 in the owner's transaction. A
// released entry is never edited. Version 0 is no texel schema.
const std::array<const char*, 2> server_migrations = {
    R"sql(
CREATE SCHEMA texel;
CREATE TABLE texel.meta (key text PRIMARY KEY, value text NOT NULL);
INSERT INTO texel.meta VALUES ('application', 'texel-experiment'), ('schema_version', '0'), ('lease_ttl_s', '30');
CREATE TABLE texel.sessions (
  id             bigserial UNIQUE,
  station        text NOT NULL,
  uuid           uuid NOT NULL UNIQUE,
  local_id       bigint NOT NULL,
  participant    text NOT NULL CHECK (length(participant) BETWEEN 1 AND 32),
  protocol       text NOT NULL,
  study          text NOT NULL,
  protocol_json  text NOT NULL,
  seed           text NOT NULL,
  simulate       text NOT NULL DEFAULT '',
  trials_planned integer NOT NULL DEFAULT -1,
  created_at     text NOT NULL,
  server_at      timestamptz NOT NULL DEFAULT clock_timestamp(),
  PRIMARY KEY (station, uuid)
);
CREATE INDEX sessions_by_participant ON texel.sessions(participant, protocol);
CREATE TABLE texel.trials (
  station       text NOT NULL,
  session_uuid  uuid NOT NULL,
  trial         integer NOT NULL CHECK (trial >= 0),
  question_json text NOT NULL,
  response_json text NOT NULL,
  state_json    text NOT NULL,
  row_json      text NOT NULL,
  stored_at     text NOT NULL,
  server_at     timestamptz NOT NULL DEFAULT clock_timestamp(),
  PRIMARY KEY (station, session_uuid, trial),
  FOREIGN KEY (station, session_uuid) REFERENCES texel.sessions(station, uuid)
);
CREATE TABLE texel.events (
  station      text NOT NULL,
  session_uuid uuid NOT NULL,
  trial        integer NOT NULL,
  seq          integer NOT NULL,
  t_s          double precision NOT NULL,
  kind         text NOT NULL,
  detail       text NOT NULL,
  at           text NOT NULL,
  PRIMARY KEY (station, session_uuid, trial, seq),
  FOREIGN KEY (station, session_uuid, trial) REFERENCES texel.trials(station, session_uuid, trial)
);
CREATE TABLE texel.completions (
  station      text NOT NULL,
  session_uuid uuid NOT NULL,
  trials       integer NOT NULL,
  completed_at text NOT NULL,
  server_at    timestamptz NOT NULL DEFAULT clock_timestamp(),
  PRIMARY KEY (station, session_uuid),
  FOREIGN KEY (station, session_uuid) REFERENCES texel.sessions(station, uuid)
);
CREATE TABLE texel.leases (
  participant  text NOT NULL,
  protocol     text NOT NULL,
  station      text NOT NULL,
  session_uuid uuid NOT NULL,
  holder       text NOT NULL,
  taken_at     timestamptz NOT NULL,
  heartbeat    timestamptz NOT NULL,
  PRIMARY KEY (participant, protocol)
);
CREATE TABLE texel.station_progress (
  station             text PRIMARY KEY,
  host                text NOT NULL,
  trials_local        bigint NOT NULL,
  trials_shipped      bigint NOT NULL,
  sessions_local      integer NOT NULL,
  completions_pending integer NOT NULL,
  oldest_unshipped_at text NOT NULL,
  reported_at         timestamptz NOT NULL DEFAULT clock_timestamp()
);

-- The study-wide writer lock: one station per (participant, protocol). A
-- station takes it over from another only when that one's heartbeat is older
-- than meta.lease_ttl_s; the same station (its own local lock decides) always.
CREATE FUNCTION texel.take_lease(p_participant text, p_protocol text, p_session uuid, p_holder text) RETURNS text
LANGUAGE plpgsql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
DECLARE
  l texel.leases%ROWTYPE;
  ttl double precision := (SELECT value::double precision FROM texel.meta WHERE key = 'lease_ttl_s');
BEGIN
  INSERT INTO texel.leases VALUES (p_participant, p_protocol, session_user, p_session, p_holder, clock_timestamp(), clock_timestamp())
    ON CONFLICT DO NOTHING;
  IF FOUND THEN RETURN ''; END IF;
  SELECT * INTO l FROM texel.leases WHERE participant = p_participant AND protocol = p_protocol FOR UPDATE;
  IF l.station <> session_user AND l.heartbeat > clock_timestamp() - make_interval(secs => ttl) THEN
    RETURN 'station ' || l.station || ' (' || l.holder || ') since '
           || to_char(l.taken_at AT TIME ZONE 'UTC', 'YYYY-MM-DD"T"HH24:MI:SS"Z"');
  END IF;
  UPDATE texel.leases SET station = session_user, session_uuid = p_session, holder = p_holder,
         taken_at = CASE WHEN l.station = session_user THEN l.taken_at ELSE clock_timestamp() END, heartbeat = clock_timestamp()
   WHERE participant = p_participant AND protocol = p_protocol;
  RETURN '';
END $$;
CREATE FUNCTION texel.renew_lease(p_session uuid) RETURNS boolean
LANGUAGE sql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
  WITH r AS (UPDATE texel.leases SET heartbeat = clock_timestamp()
              WHERE session_uuid = p_session AND station = session_user RETURNING 1)
  SELECT EXISTS (SELECT 1 FROM r);
$$;
CREATE FUNCTION texel.release_lease(p_session uuid) RETURNS void
LANGUAGE sql SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
  DELETE FROM texel.leases WHERE session_uuid = p_session AND station = session_user;
$$;

-- Rights: stations insert their own rows and read only those (they never
-- update, delete or alter); analysts read everything; every station sees
-- every station's progress (no participant data in it); the owner alone
-- changes the schema.
REVOKE ALL ON SCHEMA texel FROM PUBLIC;
GRANT USAGE ON SCHEMA texel TO texel_station, texel_analyst;
GRANT SELECT ON texel.meta TO texel_station, texel_analyst;
GRANT SELECT, INSERT ON texel.sessions, texel.trials, texel.events, texel.completions TO texel_station;
GRANT SELECT, INSERT, UPDATE ON texel.station_progress TO texel_station;
GRANT USAGE ON SEQUENCE texel.sessions_id_seq TO texel_station;
GRANT SELECT ON texel.sessions, texel.trials, texel.events, texel.completions, texel.station_progress TO texel_analyst;
REVOKE ALL ON FUNCTION texel.take_lease(text, text, uuid, text), texel.renew_lease(uuid), texel.release_lease(uuid) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION texel.take_lease(text, text, uuid, text), texel.renew_lease(uuid), texel.release_lease(uuid)
  TO texel_station;
ALTER TABLE texel.sessions ENABLE ROW LEVEL SECURITY;
ALTER TABLE texel.trials ENABLE ROW LEVEL SECURITY;
ALTER TABLE texel.events ENABLE ROW LEVEL SECURITY;
ALTER TABLE texel.completions ENABLE ROW LEVEL SECURITY;
ALTER TABLE texel.station_progress ENABLE ROW LEVEL SECURITY;
CREATE POLICY station_own ON texel.sessions TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY station_own ON texel.trials TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY station_own ON texel.events TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY station_own ON texel.completions TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY station_read ON texel.station_progress FOR SELECT TO texel_station USING (true);
CREATE POLICY station_write ON texel.station_progress FOR INSERT TO texel_station WITH CHECK (station = session_user);
CREATE POLICY station_update ON texel.station_progress FOR UPDATE TO texel_station USING (station = session_user)
  WITH CHECK (station = session_user);
CREATE POLICY analyst_read ON texel.sessions FOR SELECT TO texel_analyst USING (true);
CREATE POLICY analyst_read ON texel.trials FOR SELECT TO texel_analyst USING (true);
CREATE POLICY analyst_read ON texel.events FOR SELECT TO texel_analyst USING (true);
CREATE POLICY analyst_read ON texel.completions FOR SELECT TO texel_analyst USING (true);
CREATE POLICY analyst_read ON texel.station_progress FOR SELECT TO texel_analyst USING (true);
)sql",
    // 1 → 2: the finger that explored each trial (the journal's
    // finger_traces, schema version 2), with the same rights as events.
    R"sql(
CREATE TABLE texel.finger_traces (
  station      text NOT NULL,
  session_uuid uuid NOT NULL,
  trial        integer NOT NULL,
  source       text NOT NULL CHECK (source IN ('display', 'pointer', 'simulated')),
  mode         text NOT NULL CHECK (mode IN ('', 'display-plays', 'host-streams', 'passive')),
  samples      integer NOT NULL CHECK (samples >= 0),
  trace        text NOT NULL,
  PRIMARY KEY (station, session_uuid, trial),
  FOREIGN KEY (station, session_uuid, trial) REFERENCES texel.trials(station, session_uuid, trial)
);
GRANT SELECT, INSERT ON texel.finger_traces TO texel_station;
GRANT SELECT ON texel.finger_traces TO texel_analyst;
ALTER TABLE texel.finger_traces ENABLE ROW LEVEL SECURITY;
CREATE POLICY station_own ON texel.finger_traces TO texel_station USING (station = session_user) WITH CHECK (station = session_user);
CREATE POLICY analyst_read ON texel.finger_traces FOR SELECT TO texel_analyst USING (true);
)sql",
};
static_assert(server_migrations.size() == current_server_schema);

bool valid_role(const std::string& r) {
  if (r.empty() || r.size() > 32) return false;
  if (r.rfind("pg_", 0) == 0 || r.rfind("texel_", 0) == 0) return false;
  return std::all_of(r.begin(), r.end(), [](unsigned char c) { return std::islower(c) || std::isdigit(c) || c == '_'; });
}

std::string ident(PGconn* c, const std::string& name) {
  char* q = libpq().PQescapeIdentifier(c, name.c_str(), name.size());
  std::string out = q ? q : "";
  libpq().PQfreemem(q);
  return out;
}

}  // namespace
}  // namespace pg

std::vector<std::string> init_postgres(const std::string& db, const std::vector<std::string>& stations,
                                       const std::vector<std::string>& analysts) {
  for (const auto& names : {stations, analysts})
    for (const auto& n : names)
      if (!pg::valid_role(n))
        throw InvalidArgument("role name '" + n +
                              "' is not allowed: use 1-32 characters a-z 0-9 _ (not starting with pg_ or texel_)");
  const pg::Target t = pg::parse_target(db);
  pg::ConnectFailure f;
  PGconn* c = pg::connect(t, f);
  if (!c) throw IoError("cannot connect to " + t.label + ": " + f.why);
  struct Close {
    PGconn* c;
    ~Close() { pg::libpq().PQfinish(c); }
  } close{c};
  std::vector<std::string> report;
  auto must = [&](const std::string& sql, const std::string& op) {
    pg::Result r = pg::run(c, sql);
    if (!r.ok()) {
      pg::libpq().PQclear(pg::libpq().PQexec(c, "ROLLBACK"));
      throw IoError(t.label + ": " + op + " failed: " + r.error());
    }
  };
  must("BEGIN", "starting the set-up");
  must("SELECT pg_advisory_xact_lock(1415071064)", "waiting for another set-up");  // 'TXEX'
  // Roles are the cluster's, shared by its databases: another database's
  // set-up may create them at the same moment.
  for (const char* group : {"texel_station", "texel_analyst"})
    must(std::string("DO $$ BEGIN CREATE ROLE ") + group +
             " NOLOGIN; EXCEPTION WHEN duplicate_object OR unique_violation THEN NULL; END $$",
         std::string("creating the role ") + group);
  int v = pg::server_version(c, t.label);
  pg::refuse_newer(v, t.label);
  const int from = v;
  for (; v < pg::current_server_schema; ++v) {
    must(pg::server_migrations[static_cast<std::size_t>(v)], "migrating the schema to version " + std::to_string(v + 1));
    must("UPDATE texel.meta SET value = '" + std::to_string(v + 1) + "' WHERE key = 'schema_version'",
         "setting the schema version");
  }
  report.push_back(from == v ? "schema texel is at version " + std::to_string(v)
                             : "schema texel migrated from version " + std::to_string(from) + " to " + std::to_string(v));
  auto add_role = [&](const std::string& name, const char* group) {
    const std::string id = pg::ident(c, name);
    pg::Result exists = pg::run(c, "SELECT 1 FROM pg_roles WHERE rolname = $1", {name});
    must("DO $$ BEGIN CREATE ROLE " + id + " LOGIN IN ROLE " + group +
             "; EXCEPTION WHEN duplicate_object OR unique_violation THEN GRANT " + group + " TO " + id + "; END $$",
         "creating the role " + name);
    if (exists.ok() && exists.rows() == 0)
      report.push_back("created login role " + name + " (" + group + "); set its password with psql's \\password " + name);
    else
      report.push_back("role " + name + " is a member of " + group);
  };
  for (const auto& s : stations) add_role(s, "texel_station");
  for (const auto& a : analysts) add_role(a, "texel_analyst");
  must("COMMIT", "committing the set-up");
  return report;
}

}  // namespace texel::experiment
