#!/usr/bin/env bash
# What the live view costs the graph: launch_yaml/mobile_mocap_demo.yaml (camera at 30 Hz,
# tracking, poses, evaluator, overlay in one process) for S seconds a run, six ways:
#   no bridge             the demo without its foxglove_bridge (the reference)
#   bridge, no client     the bridge serving nobody
#   1 client              one client reading every topic but the overlay, images at 30 Hz
#   20 clients            twenty such clients
#   1 stalled client      one client that subscribes to everything and never reads
#   viewer in chromium    the built-in page in headless chromium (also: each image's age when
#                         the page drew it, capture stamp to draw, one clock)
# Per run: poses/s (evaluator frames over the run), latency median/p99 (image stamp -> the
# evaluator), frames lost, the demo process's CPU (user + system over the run's steady
# part; 100 % = one core) and its peak resident memory. Prints a markdown table. Needs test/node_modules (npm ci --prefix test).
#
#   bench/viewer_bench.sh [--duration S]   (default 20 s a run: about 2.5 min)
set -uo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin_dir="${MOCAP_BIN_DIR:-$root/build/bin}"
viewer="$root/test/viewer"
duration=20
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) duration="${2:?}"; shift 2 ;;
    -h | --help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "viewer_bench.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -d "$viewer/../node_modules" ] || { echo "viewer_bench.sh: run npm ci --prefix test first" >&2; exit 1; }

work="$(mktemp -d /tmp/viewer_bench.XXXXXX)"
trap 'kill $(jobs -p) 2>/dev/null; rm -rf "$work"' EXIT
export MOCAP_DOMAIN_ID="${MOCAP_DOMAIN_ID:-$((200 + $$ % 30))}"
port=$((20000 + $$ % 20000))
demo="$root/launch_yaml/mobile_mocap_demo.yaml"
# The same demo with absolute paths, with and without its bridge (everything from the live
# view's comment on is the bridge).
sed "s|\.\./config/|$root/config/|g" "$demo" > "$work/with_bridge.yaml"
sed '/# The live view/,$d' "$work/with_bridge.yaml" > "$work/no_bridge.yaml"

cpu_ticks() { awk '{ print $14 + $15 }' "/proc/$1/stat" 2>/dev/null || echo 0; }
rows=()
run() {  # NAME FILE CLIENT_COMMAND...
  local name="$1" file="$2"
  shift 2
  local set_port=()
  grep -q "plugin: foxglove_bridge" "$file" && set_port=(--set viewer.port="$port")
  "$bin_dir/mocap_launch" "$file" --duration "$duration" "${set_port[@]}" > "$work/run.log" 2>&1 &
  local pid=$! client="" note=""
  sleep 2
  if [ $# -gt 0 ]; then
    "$@" > "$work/client.log" 2>&1 &
    client=$!
  fi
  sleep 1
  local t0 c0 t1 c1
  t0=$(date +%s.%N)
  c0=$(cpu_ticks $pid)
  sleep $((duration - 5))
  t1=$(date +%s.%N)
  c1=$(cpu_ticks $pid)
  local peak
  peak=$(awk '/^VmHWM/ { printf "%.0f", $2 / 1024 }' "/proc/$pid/status" 2>/dev/null)
  wait $pid
  [ -n "$client" ] && { kill $client 2>/dev/null; wait $client 2>/dev/null; }
  grep -q "^frames" "$work/client.log" 2>/dev/null && note="drawn: $(cat "$work/client.log")"
  local table frames lost latency
  table="$(grep -E '\]: \| [0-9]+ \| [0-9]+ \| [0-9.]+ % \|' "$work/run.log" | tail -n 1 | sed 's/^.*\]: //')"
  frames="$(echo "$table" | awk -F'|' '{ gsub(/ /, "", $2); print $2 }')"
  lost="$(echo "$table" | awk -F'|' '{ gsub(/ /, "", $3); print $3 }')"
  latency="$(echo "$table" | awk -F'|' '{ gsub(/^ +| +$/, "", $(NF - 1)); print $(NF - 1) }')"  # the last column
  local cpu rate
  cpu=$(awk -v c="$((c1 - c0))" -v t0="$t0" -v t1="$t1" -v hz="$(getconf CLK_TCK)" \
    'BEGIN { printf "%.0f", 100 * c / hz / (t1 - t0) }')
  rate=$(awk -v f="${frames:-0}" -v d="$duration" 'BEGIN { printf "%.1f", f / d }')
  rows+=("| $name | $rate | ${latency:--} | ${lost:--} | $cpu % | ${peak:--} MB | $note |")
  echo "$name: done" >&2
}

run "no bridge" "$work/no_bridge.yaml"
run "bridge, no client" "$work/with_bridge.yaml"
run "1 client" "$work/with_bridge.yaml" node "$viewer/stream_clients.mjs" "ws://127.0.0.1:$port" 1
run "20 clients" "$work/with_bridge.yaml" node "$viewer/stream_clients.mjs" "ws://127.0.0.1:$port" 20
run "1 stalled client" "$work/with_bridge.yaml" node "$viewer/load_clients.mjs" "ws://127.0.0.1:$port" 0 1 /none "$work/never"
run "viewer in chromium" "$work/with_bridge.yaml" node "$viewer/browser_latency.mjs" "http://127.0.0.1:$port/" "$((duration - 6))"

echo
echo "| run ($duration s, camera 30 Hz) | poses/s | latency ms (median, p99) | frames lost | demo process CPU | peak RSS | image to page (ms) |"
echo "|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
