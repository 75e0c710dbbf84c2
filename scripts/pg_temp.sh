#!/usr/bin/env bash
# A throw-away PostgreSQL cluster on loopback, for tests and CI (no systemd).
#
#   scripts/pg_temp.sh start DIR [PORT]   # prints the admin URL on stdout
#   scripts/pg_temp.sh stop DIR
#
# `start` installs Debian's `postgresql` package when `initdb` is missing,
# makes a cluster in DIR (trust authentication, listening on 127.0.0.1:PORT
# only, default 55432, socket in DIR), starts it and prints
# `postgres://postgres@127.0.0.1:PORT/postgres`. Run as root, the cluster
# belongs to the `postgres` user (initdb refuses root). `stop` stops it; DIR
# can then be removed. `PG_TEMP_OPTS` adds server options to `start` (e.g.
# `-c shared_preload_libraries=pg_stat_statements`).
set -euo pipefail

cmd=${1:?usage: pg_temp.sh start|stop DIR [PORT]}
dir=${2:?usage: pg_temp.sh start|stop DIR [PORT]}
port=${3:-55432}

bindir() {
    local d
    for d in /usr/lib/postgresql/*/bin; do
        [ -x "$d/initdb" ] && { echo "$d"; return; }
    done
    return 1
}

as_owner() {
    if [ "$(id -u)" -eq 0 ]; then
        runuser -u postgres -- "$@"
    else
        "$@"
    fi
}

case "$cmd" in
start)
    if ! bindir >/dev/null; then
        echo "pg_temp.sh: installing postgresql" >&2
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq postgresql >/dev/null
    fi
    bin=$(bindir)
    mkdir -p "$dir"
    [ "$(id -u)" -eq 0 ] && chown postgres: "$dir"
    if [ ! -f "$dir/data/PG_VERSION" ]; then
        as_owner "$bin/initdb" -D "$dir/data" -U postgres --auth=trust -E UTF8 --locale=C.UTF-8 >"$dir/initdb.log" 2>&1 \
            || { cat "$dir/initdb.log" >&2; exit 1; }
    fi
    # Small settings for a shared 2-core machine; fsync stays on (the tests
    # check durability through the database, not around it).
    as_owner "$bin/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 start \
        -o "-c listen_addresses=127.0.0.1 -p $port -k $dir -c max_connections=300 -c shared_buffers=64MB ${PG_TEMP_OPTS:-}" >/dev/null \
        || { cat "$dir/server.log" >&2; exit 1; }
    echo "postgres://postgres@127.0.0.1:$port/postgres"
    ;;
stop)
    bin=$(bindir)
    as_owner "$bin/pg_ctl" -D "$dir/data" -m fast -w stop >/dev/null
    ;;
*)
    echo "usage: pg_temp.sh start|stop DIR [PORT]" >&2
    exit 2
    ;;
esac
