// JSON views of the store's result types (store.hpp, json_views.hpp): the
// one serialiser of a session and of the status report.
#include <cmath>

#include "json_views.hpp"
#include "texel/error.hpp"
#include "texel/experiment/session_state.hpp"
#include "texel/experiment/store.hpp"

namespace texel::experiment {

using nlohmann::ordered_json;

ordered_json session_view(const SessionInfo& s) {
  ordered_json j;
  j["id"] = s.id;
  j["participant"] = s.participant;
  j["protocol"] = s.protocol;
  j["study"] = s.study;
  j["status"] = s.status;
  j["finished"] = s.status == "finished";
  // The store alone: finished or stopped; a front door that holds the
  // session overwrites it with running / paused (session_state.hpp).
  j["state"] = to_string(session_state(s));
  j["trials_done"] = s.trials_done;
  j["trials_planned"] = s.trials_planned;
  j["seed"] = s.seed;
  j["simulate"] = s.simulate;
  j["simulated"] = !s.simulate.empty();
  j["created_at"] = s.created_at;
  j["updated_at"] = s.updated_at;
  return j;
}

std::string to_json(const SessionInfo& s) { return session_view(s).dump(); }

std::string to_json(const ShipStatus& s) {
  return ordered_json{{"station", s.station},
                      {"server", s.server},
                      {"journal", s.journal},
                      {"connected", s.connected},
                      {"error", s.last_error},
                      {"trials_local", s.trials_local},
                      {"trials_shipped", s.trials_shipped},
                      {"sessions_local", s.sessions_local},
                      {"completions_pending", s.completions_pending},
                      {"lag_s", s.lag_s},
                      {"conflicts", s.conflicts}}
      .dump();
}

std::string stations_json(const Store& store) {
  ordered_json out;
  const bool multi = store.is_station() || is_postgres(store.path());
  out["multi_station"] = multi;
  out["this_station"] = nullptr;
  if (store.is_station()) out["this_station"] = ordered_json::parse(to_json(store.shipping()));
  out["server_error"] = "";
  out["stations"] = ordered_json::array();
  if (multi) {
    try {
      out["stations"] = ordered_json::parse(store.station_rows_json());
    } catch (const Error& e) {
      out["server_error"] = e.what();
    }
  }
  return out.dump();
}

std::string status_json(const Store& store, std::string_view database, const std::optional<std::string>& participant) {
  ordered_json out;
  out["database"] = std::string(database);
  out["schema_version"] = store.schema_version();
  out["participants"] = store.participants();
  ordered_json sessions = ordered_json::array();
  for (const auto& s : store.sessions()) {
    if (participant && s.participant != *participant) continue;
    ordered_json j = session_view(s);
    // Where each block stands, from the stored rows.
    ordered_json blocks = ordered_json::object();
    for (const auto& row : store.rows(s.id)) {
      auto& b = blocks[row.block];
      if (b.is_null()) b = ordered_json::object();
      b["trials"] = b.value("trials", 0) + 1;
      if (std::isfinite(row.next_intensity) && !row.variable.empty()) {
        b["variable"] = row.variable;
        b["current_value"] = row.next_intensity;
        b["reversals"] = b.value("reversals", 0) + (row.reversal ? 1 : 0);
        b["finished"] = row.procedure_finished;
      }
    }
    j["blocks"] = blocks;
    sessions.push_back(j);
  }
  out["sessions"] = sessions;
  return out.dump();
}

}  // namespace texel::experiment
