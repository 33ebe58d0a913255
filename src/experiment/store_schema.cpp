// The experiment store's schema (store_sqlite.hpp, docs/session-store.md):
// its numbered migrations and the loop that applies them.
#include <array>
#include <string>

#include "store_sqlite.hpp"

namespace texel::experiment::store_parts {
namespace {

// Schema migrations, numbered: migrations[v] takes a database from schema
// version v to v + 1, in one transaction that also sets user_version. A
// released entry is never edited; a change to the schema appends one.
// Version 0 is an empty file.
const std::array<const char*, 2> migrations = {
    // 0 → 1: the first schema.
    R"sql(
CREATE TABLE participants (
  code       TEXT PRIMARY KEY CHECK (length(code) BETWEEN 1 AND 32),
  created_at TEXT NOT NULL
);
CREATE TABLE sessions (
  id             INTEGER PRIMARY KEY,
  participant    TEXT NOT NULL REFERENCES participants(code),
  protocol       TEXT NOT NULL,
  study          TEXT NOT NULL,
  protocol_json  TEXT NOT NULL,
  seed           TEXT NOT NULL,
  simulate       TEXT NOT NULL DEFAULT '',
  status         TEXT NOT NULL DEFAULT 'running' CHECK (status IN ('running', 'finished')),
  trials_planned INTEGER NOT NULL DEFAULT -1,
  created_at     TEXT NOT NULL,
  updated_at     TEXT NOT NULL
);
CREATE INDEX sessions_by_participant ON sessions(participant, protocol);
CREATE TABLE trials (
  session_id    INTEGER NOT NULL REFERENCES sessions(id),
  trial         INTEGER NOT NULL CHECK (trial >= 0),
  question_json TEXT NOT NULL,
  response_json TEXT NOT NULL,
  state_json    TEXT NOT NULL,
  row_json      TEXT NOT NULL,
  stored_at     TEXT NOT NULL,
  PRIMARY KEY (session_id, trial)
);
CREATE TABLE events (
  session_id INTEGER NOT NULL,
  trial      INTEGER NOT NULL,
  seq        INTEGER NOT NULL,
  t_s        REAL NOT NULL,
  kind       TEXT NOT NULL,
  detail     TEXT NOT NULL,
  at         TEXT NOT NULL,
  PRIMARY KEY (session_id, trial, seq),
  FOREIGN KEY (session_id, trial) REFERENCES trials(session_id, trial)
);
CREATE TABLE writers (
  session_id    INTEGER PRIMARY KEY REFERENCES sessions(id),
  pid           INTEGER NOT NULL,
  process_start INTEGER NOT NULL,
  host          TEXT NOT NULL,
  acquired_at   TEXT NOT NULL
);
)sql",
    // 1 → 2: the finger that explored each trial (finger_trace.hpp): its
    // source, the presentation mode and the samples ("t_s,x_mm,touch" lines
    // on the source's own clock). Trials stored before have no row here.
    R"sql(
CREATE TABLE finger_traces (
  session_id INTEGER NOT NULL,
  trial      INTEGER NOT NULL,
  source     TEXT NOT NULL CHECK (source IN ('display', 'pointer', 'simulated')),
  mode       TEXT NOT NULL CHECK (mode IN ('', 'display-plays', 'host-streams', 'passive')),
  samples    INTEGER NOT NULL CHECK (samples >= 0),
  trace      TEXT NOT NULL,
  PRIMARY KEY (session_id, trial),
  FOREIGN KEY (session_id, trial) REFERENCES trials(session_id, trial)
);
)sql",
};
static_assert(migrations.size() == Store::current_schema_version);

}  // namespace

void migrate(StoreImpl& s) {
  while (s.version < Store::current_schema_version) {
    const int from = s.version;
    Transaction tx(s, "migrating the schema from version " + std::to_string(from));
    // Re-read inside the write lock: another process may have migrated meanwhile.
    const auto v = static_cast<int>(pragma_int(s, "PRAGMA user_version", "reading the schema version"));
    if (v != from) {
      s.version = v;
      continue;
    }
    exec(s, migrations[static_cast<std::size_t>(from)], "migrating the schema to version " + std::to_string(from + 1));
    const std::string set =
        "PRAGMA application_id = " + std::to_string(texel_application_id) + "; PRAGMA user_version = " + std::to_string(from + 1);
    exec(s, set.c_str(), "setting the schema version");
    tx.commit();
    s.version = from + 1;
  }
}

}  // namespace texel::experiment::store_parts
