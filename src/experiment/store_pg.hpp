// The PostgreSQL side of the session store (store_pg*.cpp; docs/session-store.md
// "Many stations"): a reader of the server, and a station's shipper that
// copies its local SQLite journal to the server in the background. libpq
// types stay in store_pg*.cpp and store_pg_parts.hpp.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "texel/experiment/store.hpp"

namespace texel::experiment::pg {

/// The server's schema version this build writes and reads.
constexpr int current_server_schema = 2;

/// Reads the server through a role's rights (status, export, analyze).
class Reader {
 public:
  virtual ~Reader() = default;
  [[nodiscard]] virtual const std::string& label() const = 0;
  [[nodiscard]] virtual int schema_version() const = 0;
  [[nodiscard]] virtual std::vector<SessionInfo> sessions() const = 0;
  [[nodiscard]] virtual std::vector<std::string> participants() const = 0;
  [[nodiscard]] virtual std::vector<StoredTrial> trials(std::int64_t session_id) const = 0;
  [[nodiscard]] virtual std::vector<TrialRow> rows(std::optional<std::int64_t> session_id) const = 0;
  /// texel.station_progress as a JSON array text (stations_json()).
  [[nodiscard]] virtual std::string stations() const = 0;
};
std::shared_ptr<Reader> open_reader(const std::string& db);

/// A station's link to the server: ships the journal, holds the study-wide
/// writer lock (a lease) of the sessions this process writes.
class Station {
 public:
  virtual ~Station() = default;
  /// New trials or a completion were committed to the journal.
  virtual void poke() = 0;
  /// The study-wide lock of a session this process starts writing; throws
  /// IoError when another station holds it; offline: taken when the server
  /// is back (a conflict is then reported in status()).
  virtual void take_lease(const SessionInfo& session) = 0;
  virtual void release_lease(std::int64_t session_id) = 0;
  [[nodiscard]] virtual ShipStatus status() const = 0;
  virtual bool sync(double timeout_s) = 0;
  /// texel.station_progress as a JSON array text; throws IoError offline.
  [[nodiscard]] virtual std::string stations() = 0;
};
/// Connects once (a server that cannot be reached is not an error);
/// `journal` is open and migrated already.
std::shared_ptr<Station> start_station(const std::string& db, const std::string& journal);

}  // namespace texel::experiment::pg
