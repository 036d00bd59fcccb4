#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Starts a study cluster on this machine: N sim_manager hosts (h1..hN) on loopback, each with its own data
# dir, path prefix, HAProxy agent port and uid registry port, and HAProxy in front of them on one port, in the
# layout of deploy/haproxy/haproxy.cfg. Prints one line per host and `cluster ready: URL`, then runs until
# Ctrl-C / SIGTERM, which stops every process it started (managers end their sessions first).
#   scripts/run-cluster-demo.sh [--hosts N] [--port P] [--max-sessions N] [--build-dir DIR]
#                               [--frame-origins LIST] [--rate-limit] [--config FILE] [--run-dir DIR]
# Ports: HAProxy P (default 8080); host i: P+i, agent P+100+i, registry P+200+i; HAProxy's stats P+300.
# --config FILE is a base manager config for every host (session program, scenarios, timeouts...); the
# cluster's own settings are flags, which win over it. Without it the hosts run sim_rfb with the shipped
# scenarios. Per-address rate limits are off (every demo request comes from loopback) unless --rate-limit.
# The run dir (default BUILD_DIR/cluster-demo) keeps, per host, its data dir hN/, its log hN.log, its pid
# hN.pid and its argv hN.argv (NUL-separated, for restarting it by hand); and haproxy.cfg, haproxy.log,
# admin-token, address-key and cluster-secret (mode 0600). Restart a host by hand and write its new pid to hN.pid:
# this script still stops it at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

hosts=3
port=8080
max_sessions=4
build_dir=build
frame_origins=""
rate_limit=0
config=""
run_dir=""
usage() { sed -n '7,8p' "$0" | sed 's/^# *//' >&2; exit 2; }
need_value() { [ $# -ge 2 ] || { echo "run-cluster-demo.sh: $1 needs a value" >&2; exit 2; }; }
while [ $# -gt 0 ]; do
  case "$1" in
    --hosts) need_value "$@"; hosts="$2"; shift ;;
    --port) need_value "$@"; port="$2"; shift ;;
    --max-sessions) need_value "$@"; max_sessions="$2"; shift ;;
    --build-dir) need_value "$@"; build_dir="$2"; shift ;;
    --frame-origins) need_value "$@"; frame_origins="$2"; shift ;;
    --rate-limit) rate_limit=1 ;;
    --config) need_value "$@"; config="$2"; shift ;;
    --run-dir) need_value "$@"; run_dir="$2"; shift ;;
    -h|--help) usage ;;
    *) echo "run-cluster-demo.sh: unknown argument '$1'" >&2; usage ;;
  esac
  shift
done

# Bad input gets a clear message before anything starts.
is_count() { [[ "$1" =~ ^[1-9][0-9]*$ ]] && [ "$1" -le "$2" ]; }
is_count "$hosts" 32 || { echo "run-cluster-demo.sh: --hosts expects 1..32, not '$hosts'" >&2; exit 2; }
is_count "$max_sessions" 10000 || { echo "run-cluster-demo.sh: --max-sessions expects 1..10000" >&2; exit 2; }
{ is_count "$port" 65535 && [ "$port" -ge 1024 ] && [ $((port + 300)) -le 65535 ]; } ||
  { echo "run-cluster-demo.sh: --port expects 1024..65235 (it uses P..P+300), not '$port'" >&2; exit 2; }
manager="$build_dir/manager/sim_manager"
[ -x "$manager" ] || { echo "run-cluster-demo.sh: no $manager; build first (scripts/setup.sh)" >&2; exit 2; }
command -v haproxy >/dev/null 2>&1 ||
  { echo "run-cluster-demo.sh: needs haproxy (sudo apt-get install haproxy; Debian 12 ships 2.6)" >&2; exit 2; }
if [ -n "$config" ]; then
  [ -r "$config" ] || { echo "run-cluster-demo.sh: cannot read --config $config" >&2; exit 2; }
  config=$(realpath "$config")
fi
manager=$(realpath "$manager")
run_dir=$(realpath -m "${run_dir:-$build_dir/cluster-demo}")
mkdir -p "$run_dir"
pages="$repo/deploy/haproxy"

# Secrets: files of mode 0600 (never on a command line, where `ps` shows them). Kept across runs of the
# same run dir, so that a restarted cluster still verifies its registry's answers and the admin token holds.
umask 077
[ -s "$run_dir/cluster-secret" ] || od -An -tx1 -N32 /dev/urandom | tr -d ' \n' > "$run_dir/cluster-secret"
[ -s "$run_dir/admin-token" ] || od -An -tx1 -N16 /dev/urandom | tr -d ' \n' > "$run_dir/admin-token"
# One address key for every host, so that a participant's address hashes alike in every host's session data:
# the study's own RFBSIM_ADDRESS_KEY when set, else one kept in the run dir.
[ -n "${RFBSIM_ADDRESS_KEY:-}" ] || [ -s "$run_dir/address-key" ] || od -An -tx1 -N32 /dev/urandom | tr -d ' \n' > "$run_dir/address-key"
umask 022
admin_token=$(cat "$run_dir/admin-token")
address_key=${RFBSIM_ADDRESS_KEY:-$(cat "$run_dir/address-key")}

# Whether process PID runs (a zombie, e.g. a host killed by hand and not reaped yet, does not).
running() {
  local state=""
  { read -r _ _ state _ < "/proc/$1/stat"; } 2>/dev/null || return 1
  [ "$state" != Z ]
}

# Everything started here is stopped on the way out, however the script ends.
haproxy_pid=""
stopping=0
stop_all() {
  [ "$stopping" = 1 ] && return
  stopping=1
  trap '' INT TERM
  local pids=() i pid
  [ -n "$haproxy_pid" ] && pids+=("$haproxy_pid")
  for i in $(seq 1 "$hosts"); do
    pid=$(cat "$run_dir/h$i.pid" 2>/dev/null || true)
    [ -n "$pid" ] && pids+=("$pid")
  done
  [ ${#pids[@]} -eq 0 ] && return
  echo "cluster: stopping ${#pids[@]} process(es)" >&2
  # SIGTERM: each manager ends its sessions (SIGTERM, SIGKILL after stop_grace_s) and exits; HAProxy stops.
  kill -TERM "${pids[@]}" 2>/dev/null || true
  for _ in $(seq 1 150); do
    local alive=0
    for pid in "${pids[@]}"; do running "$pid" && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.1
  done
  kill -KILL "${pids[@]}" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -f "$run_dir"/h*.pid "$run_dir/haproxy.pid" "$run_dir/haproxy.sock"
}
trap 'stop_all' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# The registry's peers: every host, this one included.
peers=""
for i in $(seq 1 "$hosts"); do peers+="${peers:+,}h$i=127.0.0.1:$((port + 200 + i))"; done

start_host() {  # start_host I: host hI in the background; its pid in hI.pid
  local i=$1 id="h$1" args
  args=("$manager")
  [ -n "$config" ] && args+=(--config "$config")
  # Without a config: the demo's sim_rfb sessions with the shipped scenarios.
  [ -z "$config" ] && args+=(--scenarios warehouse,lab,tutorial)
  args+=(--host-id "$id" --path-prefix "/$id" --listen-address 127.0.0.1 --port $((port + i))
    --agent-port $((port + 100 + i)) --registry-port $((port + 200 + i)) --cluster-peers "$peers"
    --cluster-secret-file "$run_dir/cluster-secret" --trusted-proxies 127.0.0.1 --data-dir "$run_dir/$id"
    --max-sessions "$max_sessions")
  [ -n "$frame_origins" ] && args+=(--frame-origins "$frame_origins")
  # Every demo request comes from loopback, so per-address limits would count all participants as one.
  [ "$rate_limit" = 0 ] && args+=(--rate-start-per-minute 0 --rate-upgrade-per-minute 0
    --max-unspent-sessions-per-address 0 --max-connections-per-address 0)
  printf '%s\0' "${args[@]}" > "$run_dir/$id.argv"
  mkdir -p "$run_dir/$id"
  RFBSIM_ADMIN_TOKEN="$admin_token" RFBSIM_ADDRESS_KEY="$address_key" "${args[@]}" > "$run_dir/$id.log" 2>&1 < /dev/null &
  echo $! > "$run_dir/$id.pid"
}

# HAProxy's config: the template's structure (deploy/haproxy/haproxy.cfg) for N loopback hosts, plain HTTP.
write_haproxy_config() {
  local i id cfg="$run_dir/haproxy.cfg"
  {
    echo "# Written by scripts/run-cluster-demo.sh from the structure of deploy/haproxy/haproxy.cfg."
    echo "global"
    echo "    log stdout format raw local0 info"
    echo "    hard-stop-after 2h"
    echo "    stats socket $run_dir/haproxy.sock mode 600 level admin"
    echo "defaults"
    echo "    mode http"
    echo "    log global"
    echo "    option httplog"
    echo "    option dontlognull"
    echo "    timeout connect 2s"
    echo "    timeout client 60s"
    echo "    timeout server 60s"
    echo "    timeout http-request 10s"
    echo "    timeout http-keep-alive 10s"
    echo "    timeout tunnel 1h"
    echo "    timeout client-fin 5s"
    echo "    timeout server-fin 5s"
    echo "frontend public"
    echo "    bind 127.0.0.1:$port"
    echo "    http-request del-header X-Forwarded-For"
    echo "    option forwardfor"
    for i in $(seq 1 "$hosts"); do
      id="h$i"
      echo "    http-request return status 410 content-type application/json hdr Cache-Control no-store" \
        "string '{\"state\":\"lost\",\"ends_as\":\"lost\"}' if { path_reg ^/$id/s/[^/]+/status\$ } { nbsrv(host_$id) lt 1 }"
      echo "    http-request return status 503 content-type \"text/html; charset=utf-8\" hdr Cache-Control no-store" \
        "file $pages/session-lost.html if { path_beg /$id/ } { nbsrv(host_$id) lt 1 }"
    done
    for i in $(seq 1 "$hosts"); do echo "    use_backend host_h$i if { path_beg /h$i/ }"; done
    echo "    default_backend pool"
    echo "backend pool"
    echo "    balance url_param uid"
    echo "    hash-type consistent"
    echo "    option httpchk"
    echo "    http-check send meth GET uri /healthz ver HTTP/1.1 hdr Host rfbsim-check"
    echo "    http-check expect status 200"
    echo "    default-server inter 1s fall 2 rise 1 weight 100 agent-check agent-inter 1s"
    echo "    retry-on conn-failure empty-response"
    echo "    retries 2"
    echo "    option redispatch 1"
    echo "    http-error status 503 content-type \"text/html; charset=utf-8\" hdr Retry-After 10 hdr Cache-Control no-store" \
      "file $pages/busy.html"
    echo "    http-response set-header X-Rfbsim-Host %s"
    for i in $(seq 1 "$hosts"); do
      echo "    server h$i 127.0.0.1:$((port + i)) check agent-port $((port + 100 + i))" \
        "observe layer7 error-limit 1 on-error mark-down"
    done
    for i in $(seq 1 "$hosts"); do
      echo "    server h${i}_full 127.0.0.1:$((port + i)) backup check no-agent-check"
    done
    echo "    option allbackups"
    for i in $(seq 1 "$hosts"); do
      echo "backend host_h$i"
      echo "    server h$i 127.0.0.1:$((port + i)) check inter 1s fall 2 rise 1" \
        "observe layer4 error-limit 1 on-error mark-down"
      echo "    http-error status 503 content-type \"text/html; charset=utf-8\" hdr Cache-Control no-store" \
        "file $pages/session-lost.html"
    done
    echo "listen stats"
    echo "    bind 127.0.0.1:$((port + 300))"
    echo "    stats enable"
    echo "    stats uri /stats"
    echo "    stats refresh 5s"
  } > "$cfg"
  haproxy -c -q -f "$cfg" || { echo "run-cluster-demo.sh: HAProxy rejected $cfg" >&2; exit 1; }
}

# One HTTP GET on loopback with bash alone; prints the response ("" when nothing answered).
http_get() {
  timeout 2 bash -c 'exec 3<>"/dev/tcp/127.0.0.1/$1" && printf "GET $2 HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n" >&3 &&
    cat <&3' _ "$1" "$2" 2>/dev/null || true
}

for i in $(seq 1 "$hosts"); do start_host "$i"; done
# Each manager prints "sim_manager ready: URL" once it listens; one that exits instead shows its log.
for i in $(seq 1 "$hosts"); do
  for tries in $(seq 1 300); do
    grep -q "sim_manager ready:" "$run_dir/h$i.log" 2>/dev/null && break
    if ! running "$(cat "$run_dir/h$i.pid")" || [ "$tries" = 300 ]; then
      echo "run-cluster-demo.sh: host h$i did not start; $run_dir/h$i.log says:" >&2
      tail -n 20 "$run_dir/h$i.log" >&2
      exit 1
    fi
    sleep 0.1
  done
done

write_haproxy_config
# -W: master-worker, so SIGUSR2 to the master (haproxy.pid) reloads the config without dropping WebSockets.
haproxy -W -db -f "$run_dir/haproxy.cfg" -p "$run_dir/haproxy.pid" > "$run_dir/haproxy.log" 2>&1 < /dev/null &
haproxy_pid=$!
# Ready when HAProxy's own stats say every host is up in the pool (its health check and agent both passed).
for tries in $(seq 1 150); do
  [ "$(http_get $((port + 300)) '/stats;csv' | grep -c '^pool,h[0-9]*,.*,UP,')" = "$hosts" ] && break
  if ! running "$haproxy_pid" || [ "$tries" = 150 ]; then
    echo "run-cluster-demo.sh: HAProxy did not come up; $run_dir/haproxy.log says:" >&2
    tail -n 20 "$run_dir/haproxy.log" >&2
    exit 1
  fi
  sleep 0.1
done

for i in $(seq 1 "$hosts"); do
  echo "host h$i pid $(cat "$run_dir/h$i.pid") port $((port + i)) data $run_dir/h$i"
done
echo "haproxy pid $haproxy_pid config $run_dir/haproxy.cfg stats http://127.0.0.1:$((port + 300))/stats"
echo "admin: http://127.0.0.1:$port/h1/admin (token in $run_dir/admin-token)"
echo "participant link: http://127.0.0.1:$port/start?uid=demo"
echo "cluster ready: http://127.0.0.1:$port/"

# Run until Ctrl-C / SIGTERM. A host killed or restarted by hand does not end the cluster.
while :; do
  sleep 1 &
  wait $! || true
done
