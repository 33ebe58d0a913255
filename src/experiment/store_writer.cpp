// The writer lock of a session (store.hpp, docs/session-store.md): one
// process writes a session at a time, recorded in the writers table with its
// host, pid and start time, so a lock left by a dead run (killed, crashed) is
// recognised and taken over, and a live one refused in one line.
#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "store_sqlite.hpp"

namespace texel::experiment {
namespace store_parts {

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

namespace {

// /proc/<pid>/stat: the state (field 3) and the start time in clock ticks
// since boot (field 22). The start time tells a recycled pid from the writer.
struct ProcStat {
  bool readable = false;
  char state = '?';
  std::int64_t start = 0;
};
ProcStat proc_stat(std::int64_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ProcStat s;
  const auto close = text.rfind(')');  // the command name may hold spaces and parentheses
  if (close == std::string::npos) return s;
  std::istringstream rest(text.substr(close + 1));
  std::string field;
  // After ')': field 3 is the state; field 22 is 20 further on.
  rest >> s.state;
  for (int f = 4; f <= 22; ++f) {
    if (!(rest >> field)) return s;
  }
  try {
    s.start = std::stoll(field);
  } catch (const std::exception&) {
    return s;
  }
  s.readable = true;
  return s;
}

// Is `pid` (started at `start` ticks) still running on this machine? A
// zombie counts as dead: it holds nothing and will never write again.
bool process_alive(std::int64_t pid, std::int64_t start) {
  if (pid <= 0 || pid > std::numeric_limits<pid_t>::max()) return false;
  if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno != EPERM) return false;
  const ProcStat s = proc_stat(pid);
  if (!s.readable) return true;  // no /proc: trust kill()
  if (s.state == 'Z' || s.state == 'X') return false;
  return s.start == start;
}

std::string session_label(const SessionInfo& s) {
  return "session " + std::to_string(s.id) + " (" + s.participant + ", " + s.protocol + ")";
}

}  // namespace

// Our own start time; recomputed after a fork(), where the child inherits
// the parent's cached value.
std::int64_t own_start() {
  static pid_t cached_pid = 0;
  static std::int64_t start = 0;
  if (cached_pid != ::getpid()) {
    cached_pid = ::getpid();
    start = proc_stat(cached_pid).start;
  }
  return start;
}

void check_lock(const StoreImpl& s, const std::shared_ptr<StoreImpl>& mine, const WriterLock& lock,
                const std::shared_ptr<StoreImpl>& lock_impl, const std::string& op) {
  if (!lock_impl) throw InvalidArgument(op + ": the writer lock was released or moved from");
  if (lock_impl != mine) throw InvalidArgument(op + ": the writer lock belongs to another Store");
  Stmt st(s, "SELECT pid, process_start FROM writers WHERE session_id = ?", op);
  st.bind(1, lock.session_id());
  if (!st.step() || st.i64(0) != ::getpid() || st.i64(1) != own_start())
    throw IoError(s.path + ": " + op + ": this process no longer holds the writer lock of session " +
                  std::to_string(lock.session_id()));
}

}  // namespace store_parts

using namespace store_parts;

WriterLock Store::acquire_writer(std::int64_t session_id) {
  if (!impl_->writable || impl_->reader)
    throw InvalidArgument(impl_->path + " is open read-only; cannot write session " + std::to_string(session_id));
  const SessionInfo info = session(session_id);
  const std::string op = "taking the writer lock of " + session_label(info);
  Transaction tx(*impl_, op);
  const std::string host = host_name();
  {
    Stmt st(*impl_, "SELECT pid, process_start, host, acquired_at FROM writers WHERE session_id = ?", op);
    st.bind(1, session_id);
    if (st.step()) {
      const std::int64_t pid = st.i64(0), start = st.i64(1);
      const std::string other_host = st.text(2), since = st.text(3);
      if (other_host != host)
        throw IoError(session_label(info) + " is being written by process " + std::to_string(pid) + " on host " + other_host +
                      " since " + since +
                      "; stop it first (a lock from another machine is not checked; if that run is gone, "
                      "delete its row from the writers table)");
      if (pid == ::getpid() && start == own_start())
        throw IoError(session_label(info) + " is already being written by this process (since " + since + ")");
      if (process_alive(pid, start))
        throw IoError(session_label(info) + " is being written by process " + std::to_string(pid) + " since " + since +
                      "; stop it first");
      // Otherwise the row is left by a dead run (killed, crashed): take it over.
    }
  }
  Stmt(*impl_,
       "INSERT INTO writers(session_id, pid, process_start, host, acquired_at) VALUES (?, ?, ?, ?, ?) "
       "ON CONFLICT(session_id) DO UPDATE SET pid = excluded.pid, process_start = excluded.process_start, "
       "host = excluded.host, acquired_at = excluded.acquired_at",
       op)
      .bind(1, session_id)
      .bind(2, static_cast<std::int64_t>(::getpid()))
      .bind(3, own_start())
      .bind(4, host)
      .bind(5, utc_timestamp())
      .run();
  tx.commit();
  WriterLock lock(impl_, session_id);
  // A station also holds the study-wide lock (a refusal releases ours).
  if (impl_->station) impl_->station->take_lease(info);
  return lock;
}

// ---------------------------------------------------------------------------
// WriterLock

WriterLock::WriterLock(std::shared_ptr<StoreConnection> impl, std::int64_t session_id)
    : impl_(std::move(impl)), session_id_(session_id) {}
WriterLock::WriterLock(WriterLock&& o) noexcept : impl_(std::move(o.impl_)), session_id_(o.session_id_) {}
WriterLock& WriterLock::operator=(WriterLock&& o) noexcept {
  if (this != &o) {
    WriterLock old(std::move(*this));
    impl_ = std::move(o.impl_);
    session_id_ = o.session_id_;
  }
  return *this;
}
WriterLock::~WriterLock() {
  if (!impl_ || !impl_->db) return;
  // Only our own row: if another process took the session over, leave it.
  sqlite3_stmt* st = nullptr;
  if (sqlite3_prepare_v2(impl_->db, "DELETE FROM writers WHERE session_id = ? AND pid = ? AND process_start = ?", -1, &st,
                         nullptr) == SQLITE_OK) {
    sqlite3_bind_int64(st, 1, session_id_);
    sqlite3_bind_int64(st, 2, ::getpid());
    sqlite3_bind_int64(st, 3, own_start());
    sqlite3_step(st);  // a failure leaves a row that the next run recognises as dead
  }
  sqlite3_finalize(st);
  if (impl_->station) impl_->station->release_lease(session_id_);
}

}  // namespace texel::experiment
