#!/usr/bin/env bash
# TLS through the compose proxy, checked against a real service on this host:
# deploy/haproxy.cfg + deploy/haproxy-tls.cfg (the files compose.tls.yaml
# loads) in front of `robocal serve` with a key from `robocal keygen`, a
# self-signed CA and server certificate made here. Checks: /healthz over
# HTTPS with the CA; a write without the key 401, with it 201; plain HTTP to
# the TLS port gets no answer; a client that does not trust the CA is refused.
#
#   scripts/tls_check.sh target/debug/robocal
#
# Installs Debian's haproxy when it is missing. The configs are the shipped
# ones with only the addresses moved to loopback ports (the backend's
# hostnames robocal-a/-b to this service, the binds to 127.0.0.1).
set -euo pipefail
BIN=${1:?usage: tls_check.sh path/to/robocal}
BIN=$(realpath "$BIN")
cd "$(dirname "$0")/.."
if ! command -v haproxy >/dev/null; then
    echo "tls_check: installing haproxy" >&2
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq haproxy >/dev/null
fi
WORK=$(mktemp -d)
PIDS=()
cleanup() {
    for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
    rm -rf "$WORK"
}
trap cleanup EXIT
fail() { echo "tls_check: FAILED: $*" >&2; for f in "$WORK"/*.log; do echo "--- $f" >&2; tail -20 "$f" >&2; done; exit 1; }
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }

# A CA and a server certificate for localhost signed by it.
openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj "/CN=robocal test CA" \
    -keyout "$WORK/ca.key" -out "$WORK/ca.pem" 2>/dev/null
openssl req -newkey rsa:2048 -nodes -subj "/CN=localhost" -keyout "$WORK/server.key" -out "$WORK/server.csr" 2>/dev/null
printf 'subjectAltName=DNS:localhost,IP:127.0.0.1\n' >"$WORK/san.ext"
openssl x509 -req -in "$WORK/server.csr" -CA "$WORK/ca.pem" -CAkey "$WORK/ca.key" -CAcreateserial -days 2 \
    -extfile "$WORK/san.ext" -out "$WORK/server.pem" 2>/dev/null
mkdir -p "$WORK/tls"
cat "$WORK/server.pem" "$WORK/server.key" >"$WORK/tls/robocal.pem"

ENTRY=$("$BIN" keygen --role admin)
KEY=${ENTRY%:*}
API_PORT=$(free_port); HTTP_PORT=$(free_port); TLS_PORT=$(free_port)
ROBOCAL_API_KEYS=$ENTRY RUST_LOG=warn "$BIN" serve --bind "127.0.0.1:$API_PORT" \
    --database-url "sqlite://$WORK/tls.db?mode=rwc" >"$WORK/robocal.log" 2>&1 &
PIDS+=($!)

sed -e "s/bind :8080/bind 127.0.0.1:$HTTP_PORT/" \
    -e "s/robocal-[ab]:8080/127.0.0.1:$API_PORT/" \
    -e 's/^    log stdout.*$//' deploy/haproxy.cfg >"$WORK/haproxy.cfg"
sed -e "s/bind :8443/bind 127.0.0.1:$TLS_PORT/" \
    -e "s#/etc/haproxy/tls/#$WORK/tls/#" deploy/haproxy-tls.cfg >"$WORK/haproxy-tls.cfg"
haproxy -c -q -f "$WORK/haproxy.cfg" -f "$WORK/haproxy-tls.cfg" >/dev/null || fail "haproxy rejects the configs"
haproxy -db -f "$WORK/haproxy.cfg" -f "$WORK/haproxy-tls.cfg" >"$WORK/haproxy.log" 2>&1 &
PIDS+=($!)

BASE=https://localhost:$TLS_PORT
for _ in $(seq 1 120); do
    curl -fsS --max-time 2 --cacert "$WORK/ca.pem" --resolve "localhost:$TLS_PORT:127.0.0.1" "$BASE/readyz" >/dev/null 2>&1 && break
    sleep 0.5
done
c() { curl -sS --max-time 10 --cacert "$WORK/ca.pem" --resolve "localhost:$TLS_PORT:127.0.0.1" "$@"; }
health=$(c -o /dev/null -w '%{http_code}' "$BASE/healthz") || fail "no HTTPS answer"
[[ "$health" == 200 ]] || fail "/healthz over HTTPS answered $health"
code=$(c -o /dev/null -w '%{http_code}' -X POST "$BASE/v1/robots" -H 'Content-Type: application/json' -d '{"preset":"ur5"}')
[[ "$code" == 401 ]] || fail "a write without the key answered $code over HTTPS, not 401"
code=$(c -o /dev/null -w '%{http_code}' -X POST "$BASE/v1/robots" -H "Authorization: Bearer $KEY" \
    -H 'Content-Type: application/json' -d '{"preset":"ur5"}')
[[ "$code" == 201 ]] || fail "a write with the key answered $code over HTTPS, not 201"
hsts=$(c -sI "$BASE/healthz" | tr -d '\r' | grep -i '^strict-transport-security' || true)
[[ -n "$hsts" ]] || fail "no Strict-Transport-Security header"
if curl -fsS --max-time 5 "http://127.0.0.1:$TLS_PORT/healthz" >/dev/null 2>&1; then
    fail "plain HTTP on the TLS port answered"
fi
if curl -fsS --max-time 5 --resolve "localhost:$TLS_PORT:127.0.0.1" "$BASE/healthz" >/dev/null 2>&1; then
    fail "a client without the CA was not refused"
fi
echo "tls_check: OK: HTTPS on the compose proxy's TLS frontend: /healthz 200, write 401 without the key and 201 with it, HSTS set, plain HTTP and untrusted clients refused"
