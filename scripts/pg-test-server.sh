#!/usr/bin/env bash
# A throw-away PostgreSQL server for the store's tests and benchmark
# (docs/session-store.md "Tests"): initdb + pg_ctl in a temporary directory,
# as an unprivileged user (nobody when run as root), listening only on a
# Unix socket in that directory and on 127.0.0.1 at a free port.
#
#   scripts/pg-test-server.sh start ENV_FILE   start; write the connection to ENV_FILE
#   scripts/pg-test-server.sh stop ENV_FILE    stop it and remove its directory
#   scripts/pg-test-server.sh down ENV_FILE    stop it as a crash would (immediate), keeping its data
#   scripts/pg-test-server.sh up ENV_FILE      start it again after down
#
# ENV_FILE (shell syntax) sets TEXEL_PG_DIR, TEXEL_PG_BIN, TEXEL_PG_SOCKET,
# TEXEL_PG_PORT, TEXEL_PG_ADMIN (the superuser: trust on the socket only) and
# TEXEL_PG_AS (the command prefix that runs a server binary as its user).
# TEXEL_PG_EXTRA_OPTS adds server settings (the benchmark: -c track_commit_timestamp=on).
# Over TCP every role authenticates with a SCRAM password.
set -euo pipefail

cmd=${1:-}
env_file=${2:-}
[ -n "$cmd" ] && [ -n "$env_file" ] || { echo "usage: $0 start|stop|down|up ENV_FILE" >&2; exit 2; }

pg_bin() {
  local d
  d=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -1)
  [ -n "$d" ] && [ -x "$d/initdb" ] || { echo "pg-test-server: no PostgreSQL server binaries (apt-get install postgresql)" >&2; exit 2; }
  echo "$d"
}

case "$cmd" in
start)
  bin=$(pg_bin)
  dir=$(mktemp -d /tmp/texel-pg.XXXXXX)
  as=()
  if [ "$(id -u)" -eq 0 ]; then
    chown nobody "$dir"
    as=(setpriv --reuid=nobody --regid=nogroup --clear-groups --)
  fi
  chmod 755 "$dir"
  port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  cd "$dir"
  "${as[@]}" "$bin/initdb" -D "$dir/data" -U texel_admin -A trust --auth-host=scram-sha-256 -E UTF8 --no-locale \
    >"$dir/initdb.log" 2>&1 || { cat "$dir/initdb.log" >&2; exit 1; }
  # The socket: trust for the admin only; every other local login needs a password too.
  cat >"$dir/data/pg_hba.conf" <<EOF
local all texel_admin trust
local all all scram-sha-256
host all all 127.0.0.1/32 scram-sha-256
EOF
  opts="-k $dir -c listen_addresses=127.0.0.1 -p $port -c max_connections=200 -c shared_buffers=32MB ${TEXEL_PG_EXTRA_OPTS:-}"
  "${as[@]}" "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 30 -o "$opts" start >/dev/null ||
    { cat "$dir/server.log" >&2; exit 1; }
  {
    echo "TEXEL_PG_DIR=$dir"
    echo "TEXEL_PG_BIN=$bin"
    echo "TEXEL_PG_SOCKET=$dir"
    echo "TEXEL_PG_PORT=$port"
    echo "TEXEL_PG_ADMIN=texel_admin"
    echo "TEXEL_PG_AS='${as[*]}'"
    echo "TEXEL_PG_OPTS='$opts'"
  } >"$env_file"
  echo "pg-test-server: PostgreSQL at 127.0.0.1:$port and $dir (data $dir/data)"
  ;;
stop)
  [ -f "$env_file" ] || exit 0
  # shellcheck disable=SC1090
  . "$env_file"
  read -r -a as <<<"${TEXEL_PG_AS:-}"
  "${as[@]}" "$TEXEL_PG_BIN/pg_ctl" -D "$TEXEL_PG_DIR/data" -m immediate -w stop >/dev/null 2>&1 || true
  case "$TEXEL_PG_DIR" in /tmp/texel-pg.*) rm -rf "$TEXEL_PG_DIR" ;; esac
  rm -f "$env_file"
  ;;
down|up)
  # shellcheck disable=SC1090
  . "$env_file"
  read -r -a as <<<"${TEXEL_PG_AS:-}"
  if [ "$cmd" = down ]; then
    "${as[@]}" "$TEXEL_PG_BIN/pg_ctl" -D "$TEXEL_PG_DIR/data" -m immediate -w stop >/dev/null
  else
    "${as[@]}" "$TEXEL_PG_BIN/pg_ctl" -D "$TEXEL_PG_DIR/data" -l "$TEXEL_PG_DIR/server.log" -w -t 60 -o "$TEXEL_PG_OPTS" start >/dev/null
  fi
  ;;
*)
  echo "usage: $0 start|stop|down|up ENV_FILE" >&2
  exit 2
  ;;
esac
