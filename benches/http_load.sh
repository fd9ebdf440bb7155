#!/usr/bin/env bash
# Load benchmark of the HTTP service (loopback only, bounded duration).
#
#  1. POST /api/v1/critical (thesis data, n = 50) with wrk: 16 connections,
#     2 threads, DURATION seconds (default 10). Target: ≥ 500 req/s, p99 ≤ 50 ms.
#  2. GET /healthz with wrk (one connection: probe latency, not saturation),
#     idle and while a 10 000-point chart job (2000 elements,
#     several seconds on two cores) runs on the job pool. Target: p99 < 5 ms.
#
# Needs `wrk` (apt-get install -y wrk) and curl. Usage:
#   benches/http_load.sh            # builds the release binary first
#   SKIP_BUILD=1 DURATION=5 benches/http_load.sh
set -euo pipefail
cd "$(dirname "$0")/.."
DURATION="${DURATION:-10}"
command -v wrk >/dev/null || { echo "wrk is missing: apt-get install -y wrk" >&2; exit 1; }
[ -n "${SKIP_BUILD:-}" ] || cargo build --release --bin tetherplan

work="$(mktemp -d)"
server_pid=""
cleanup() {
    if [ -n "$server_pid" ]; then kill -TERM "$server_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true; fi
    rm -rf "$work"
}
trap cleanup EXIT

RUST_LOG=warn ./target/release/tetherplan serve --addr 127.0.0.1:0 --db "$work/jobs.db" --static-dir "$work" \
    >"$work/stdout" 2>"$work/stderr" &
server_pid=$!
for _ in $(seq 100); do grep -q "listening on" "$work/stdout" 2>/dev/null && break; sleep 0.05; done
base="$(sed -n 's/^tetherplan listening on //p' "$work/stdout")"
[ -n "$base" ] || { echo "the server did not start:" >&2; cat "$work/stderr" >&2; exit 1; }
echo "server: $base (pid $server_pid); cores: $(nproc); load average: $(cut -d' ' -f1-3 /proc/loadavg)"

system='"cable": {"density_kg_m3": 7800.0, "area_m2": 1e-5}, "aerostat": {"net_buoyancy_n": 1000.0, "mass_kg": 10.0}'
critical="{$system, \"model\": {\"elements\": 50}, \"profile\": {\"kind\": \"constant_rate\", \"rate_m_s\": 10.0}}"
cat >"$work/critical.lua" <<LUA
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
wrk.body = '$critical'
LUA
curl -sf -H 'content-type: application/json' -d "$critical" "$base/api/v1/critical" | grep -o '"max_elevation_m":[0-9.]*'

echo
echo "== POST /api/v1/critical, n = 50, 16 connections, ${DURATION} s"
wrk -t2 -c16 -d"${DURATION}s" --latency -s "$work/critical.lua" "$base/api/v1/critical" | tee "$work/critical.txt"

echo
echo "== GET /healthz, one connection, idle server (baseline)"
wrk -t1 -c1 -d3s --latency "$base/healthz" | tee "$work/healthz-idle.txt"

echo
echo "== GET /healthz, one connection, while a 10 000-point chart job (2000 elements) runs"
job="{\"kind\": \"chart\", \"request\": {$system, \"model\": {\"elements\": 2000}, \"rates_m_s\": {\"min\": 1.0, \"max\": 120.0, \"count\": 10000}}}"
id="$(curl -sf -H 'content-type: application/json' -d "$job" "$base/api/v1/jobs" | sed 's/.*"id":\([0-9]*\).*/\1/')"
for _ in $(seq 200); do curl -sf "$base/api/v1/jobs/$id" | grep -q '"status":"running"' && break; sleep 0.02; done
echo "job $id before the run: $(curl -sf "$base/api/v1/jobs/$id" | grep -o '"status":"[a-z]*","progress":[0-9.]*')"
wrk -t1 -c1 -d3s --latency "$base/healthz" | tee "$work/healthz.txt"
echo "job $id after the run: $(curl -sf "$base/api/v1/jobs/$id" | grep -o '"status":"[a-z]*","progress":[0-9.]*')"
