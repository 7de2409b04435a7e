#!/usr/bin/env bash
# DDS Security under a long load: two secured processes (credentials from
# scripts/make_security.sh: authentication, access control, discovery, liveliness, metadata and
# data encrypted) exchange 1280x720 images at 30 Hz (synthetic_ir_camera -> fiducial_tracker)
# and a numbered reliable stream at 1 kHz (sequence_source -> sequence_sink), for M minutes,
# over shared memory and over UDP at the same time (two pairs, two DDS domains). Each pair
# passes when both processes exit 0 within M minutes + 3 (no abort, no hang) and the sink got
# every numbered message (reliable) once and in order. Images are best effort (sensor_data):
# the share that arrived is reported, not judged.
#
#   bench/secure_soak.sh [--minutes M]    (default 20)
set -uo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin_dir="${MOCAP_BIN_DIR:-$root/build/bin}"
plugins="${MOCAP_TEST_PLUGIN_DIR:-$root/build/test_plugins}"
minutes=20
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) minutes="${2:?}"; shift 2 ;;
    -h | --help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "secure_soak.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
seconds=$(awk -v m="$minutes" 'BEGIN { printf "%d", m * 60 }')
[ -d "$plugins" ] || { echo "secure_soak.sh: no test plugins in $plugins (build with tests)" >&2; exit 1; }
work="$(mktemp -d /tmp/secure_soak.XXXXXX)"
trap 'kill $(jobs -p) 2>/dev/null; wait 2>/dev/null; rm -rf "$work"' EXIT
"$root/scripts/make_security.sh" "$work/credentials" sender receiver > "$work/credentials.log" 2>&1 ||
  { cat "$work/credentials.log" >&2; exit 1; }
count=$((seconds * 1000))

pair() {  # NAME SHARED_MEMORY DOMAIN: writes the two launch files and runs them
  local name="$1" shm="$2" domain="$3" dir="$work/$1"
  mkdir -p "$dir"
  local dds="{shared_memory: $shm, security: {directory: \"$work/credentials\", identity: %s}}"
  cat > "$dir/sender.yaml" <<YAML
dds: $(printf "$dds" sender)
groups:
  - name: sender
    components:
      - plugin: synthetic_ir_camera
        name: camera
        parameters: {scene: $root/config/scenes/demo.yaml, camera: $root/config/cameras/synthetic_ir_1280x720.yaml, database: $root/config/constellations.yaml, rate_hz: 30}
      - plugin: sequence_source
        name: source
        parameters: {count: $count, batch: 10, period_s: 0.01, stop_when_done: true}
YAML
  cat > "$dir/receiver.yaml" <<YAML
dds: $(printf "$dds" receiver)
groups:
  - name: receiver
    components:
      - plugin: fiducial_tracker
        name: tracker
      - plugin: sequence_sink
        name: sink
        parameters: {expect: $count, summary_file: "$dir/summary.yaml", timeout_s: $((seconds + 120))}
YAML
  local env=(env MOCAP_DOMAIN_ID="$domain" MOCAP_PLUGIN_PATH="$plugins")
  "${env[@]}" timeout -s KILL $((seconds + 180)) "$bin_dir/mocap_launch" "$dir/receiver.yaml" > "$dir/receiver.log" 2>&1 &
  local receiver=$!
  "${env[@]}" timeout -s KILL $((seconds + 180)) "$bin_dir/mocap_launch" "$dir/sender.yaml" > "$dir/sender.log" 2>&1 &
  local sender=$!
  wait $receiver; echo $? > "$dir/receiver.status"
  wait $sender; echo $? > "$dir/sender.status"
}

start=$(date +%s)
pair shared_memory true $((150 + $$ % 20)) &
pair udp false $((170 + $$ % 20)) &
wait
elapsed=$(( $(date +%s) - start ))

failed=0
echo "| transport ($minutes min) | sender exit | receiver exit | numbered received | missing | out of order | images that arrived (of ~$((seconds * 30))) | aborts |"
echo "|---|---|---|---|---|---|---|---|"
for name in shared_memory udp; do
  dir="$work/$name"
  s=$(cat "$dir/sender.status"); r=$(cat "$dir/receiver.status")
  field() { sed -n "s/^$1: //p" "$dir/summary.yaml" 2>/dev/null; }
  images=$(sed -n 's/.*\[tracker\]: \([0-9]*\) images in all.*/\1/p' "$dir/receiver.log" | tail -n 1)
  aborts=$(grep -c "Assertion\|Aborted\|terminate called" "$dir/sender.log" "$dir/receiver.log" | awk -F: '{ n += $2 } END { print n + 0 }')
  echo "| $name | $s | $r | $(field received) | $(field missing) | $(field out_of_order) | ${images:-0} | $aborts |"
  if [ "$s" != 0 ] || [ "$r" != 0 ] || [ "$(field received)" != "$count" ] || [ "$(field missing)" != 0 ] ||
     [ "$aborts" != 0 ]; then
    failed=1
    echo "--- $name sender ---"; tail -n 20 "$dir/sender.log"
    echo "--- $name receiver ---"; tail -n 20 "$dir/receiver.log"
  fi
done
echo "elapsed: ${elapsed} s"
[ "$failed" -eq 0 ] && echo "PASS" || echo "FAIL"
exit "$failed"
