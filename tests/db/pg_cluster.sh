#!/bin/sh
# A throwaway PostgreSQL cluster for the tests (the C++ fixture tests/db/pg_cluster.cpp and the
# Python tests use it):
#   pg_cluster.sh start DIR   initdb in DIR/data, start postgres with its unix socket in DIR and
#                             on 127.0.0.1 at a free port; prints the port. As root (here and in
#                             CI) the cluster runs as `nobody` (initdb refuses root).
#                             (also written to DIR/port, for the tests that share it)
#   pg_cluster.sh stop DIR    stops it and removes DIR.
# The role is "synbench", trust authentication (nothing leaves the machine). Exit status 3 and
# a message when PostgreSQL is not installed: the tests fail on that, they do not skip.
set -eu
cmd=${1:?start|stop}
dir=${2:?DIR}

bindir() {
  if [ -n "${SYNBENCH_PG_BINDIR:-}" ]; then echo "$SYNBENCH_PG_BINDIR"; return; fi
  for d in /usr/lib/postgresql/*/bin; do
    if [ -x "$d/initdb" ]; then echo "$d"; return; fi
  done
  if command -v initdb >/dev/null 2>&1; then dirname "$(command -v initdb)"; return; fi
  echo "PostgreSQL is not installed (no initdb in /usr/lib/postgresql/*/bin or on PATH): install postgresql-15 as the README's setup does (scripts/install-deps.sh), or set SYNBENCH_PG_BINDIR" >&2
  exit 3
}

as_owner() {
  if [ "$(id -u)" = 0 ]; then runuser -u nobody -- "$@"; else "$@"; fi
}

case "$cmd" in
start)
  bin=$(bindir)
  mkdir -p "$dir"
  # Absolute, then run from /: the cluster's user may not enter the caller's directory (a fresh
  # clone under a private mktemp directory), and PostgreSQL's tools warn about that on stderr.
  dir=$(cd "$dir" && pwd)
  cd /
  if [ "$(id -u)" = 0 ]; then chown nobody "$dir"; fi
  chmod 700 "$dir"
  as_owner test -w "$dir" ||
    { echo "pg_cluster.sh: $dir is not reachable by the cluster's user (a parent directory closed to it?)" >&2; exit 1; }
  as_owner "$bin/initdb" -D "$dir/data" -A trust -U synbench -E UTF8 --locale=C --no-sync >"$dir/initdb.log" 2>&1 ||
    { cat "$dir/initdb.log" >&2; exit 1; }
  port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  as_owner "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 \
    -o "-k $dir -p $port -c listen_addresses=127.0.0.1 -c max_connections=200" start >/dev/null ||
    { cat "$dir/server.log" >&2; exit 1; }
  echo "$port" >"$dir/port"
  echo "$port"
  ;;
stop)
  if [ -d "$dir/data" ]; then
    bin=$(bindir)
    as_owner "$bin/pg_ctl" -D "$dir/data" -m immediate -w stop >/dev/null 2>&1 || true
  fi
  rm -rf "$dir"
  ;;
*)
  echo "usage: pg_cluster.sh start|stop DIR" >&2
  exit 2
  ;;
esac
