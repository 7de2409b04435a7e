#!/usr/bin/env bash
# Rate and end-to-end latency of /mocap/poses (image capture stamp -> the pose's arrival at the
# pose evaluator) for the same tracking pipeline deployed four ways, one after the other:
#   one process (demo)     launch_yaml/mobile_mocap_demo.yaml (with its overlay)
#   one process            every component of launch_yaml/distributed/tracking.yaml in one
#                          group: the distributed run's components, in-process
#   4 processes, 1 host    tracking.yaml without --group: its four groups as processes of this
#                          machine, UDP over loopback
#   4 hosts                the same groups in four network namespaces on a bridge
#                          (scripts/netns_scenario.sh --measure; needs root), the evaluator on
#                          the observer host: two network hops (fiducials sensor -> compute,
#                          poses compute -> observer)
# each with the camera at 30 Hz (latency) and at full speed (rate_hz 0: throughput). The
# namespaces share this machine's clock, so latency is the pose's arrival time minus the
# image's stamp, which the pose carries. Prints a markdown table. Every process runs on the
# DDS implementation MOCAP_DDS_IMPLEMENTATION names (default fastdds).
#
#   bench/distributed_bench.sh [--duration S] [--quick]   (default 15 s a run: about 2.5 min)
#   MOCAP_DDS_IMPLEMENTATION=cyclonedds bench/distributed_bench.sh
set -uo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin_dir="${MOCAP_BIN_DIR:-$root/build/bin}"
duration=15
while [ $# -gt 0 ]; do
  case "$1" in
    --duration) duration="${2:?}"; shift 2 ;;
    --quick) duration=8; shift ;;
    -h | --help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "distributed_bench.sh: unknown option $1" >&2; exit 2 ;;
  esac
done

work="$(mktemp -d /tmp/distributed_bench.XXXXXX)"
trap 'rm -rf "$work"' EXIT
# A domain of its own, away from the tests' (100..199).
export MOCAP_DOMAIN_ID="${MOCAP_DOMAIN_ID:-$((200 + $$ % 30))}"

rows=()
# Adds a row from an evaluator's log: its live lines ("30.0 frames/s, latency 1.2 ms, ...",
# the first two skipped as start-up) and its final table line.
add_row() {  # NAME CAMERA LOG NOTE
  local name="$1" camera="$2" log="$3" note="$4"
  local rate table
  rate="$(grep -o '[0-9.]* frames/s' "$log" | awk 'NR > 2 { print $1 }' | sort -n |
    awk '{ v[NR] = $1 } END { if (NR) printf "%.1f", v[int((NR + 1) / 2)]; else printf "-" }')"
  # | frames | lost | tracked | position | orientation | false ids | latency ms (median, p99) |
  # (The row itself, not the line after the header: other processes' lines may come between.)
  table="$(grep -E '\]: \| [0-9]+ \| [0-9]+ \| [0-9.]+ % \|' "$log" | tail -n 1 | sed 's/^.*\]: //')"
  if [ -z "$table" ]; then
    rows+=("| $name | $camera | - | - | - | - | - | no result: $(tail -n 2 "$log" | tr '\n' ' ' | cut -c1-120) |")
    return
  fi
  local frames lost tracked latency median p99
  frames="$(echo "$table" | awk -F'|' '{ gsub(/ /, "", $2); print $2 }')"
  lost="$(echo "$table" | awk -F'|' '{ gsub(/ /, "", $3); print $3 }')"
  tracked="$(echo "$table" | awk -F'|' '{ gsub(/^ +| +$/, "", $4); print $4 }')"
  latency="$(echo "$table" | awk -F'|' '{ print $8 }')"
  median="$(echo "$latency" | awk -F', ' '{ gsub(/ /, "", $1); print $1 }')"
  p99="$(echo "$latency" | awk -F', ' '{ gsub(/ /, "", $2); print $2 }')"
  rows+=("| $name | $camera | $rate | $median | $p99 | $tracked | $frames ($lost lost) | $note |")
}

# tracking.yaml's components in one group, paths made absolute.
merged="$work/one_process.yaml"
awk -v config="$root/config" '
  /^groups:/ { print; print "  - name: all"; print "    components:"; in_groups = 1; next }
  in_groups && /^  - name: / { next }
  in_groups && /^    components:/ { next }
  { gsub(/\.\.\/\.\.\/config/, config); print }' \
  "$root/launch_yaml/distributed/tracking.yaml" >"$merged"

echo "distributed_bench: ${duration} s a run, DDS domain $MOCAP_DOMAIN_ID," \
  "${MOCAP_DDS_IMPLEMENTATION:-fastdds}" >&2
servos=(--set "servos.device_link=$work/servos" --set "turret.port=$work/servos")
for rate in 30 0; do
  camera="$([ "$rate" = 0 ] && echo "full speed" || echo "$rate Hz")"
  set_rate=(--set "camera.rate_hz=$rate")

  echo "camera $camera: one process (mobile_mocap_demo.yaml) ..." >&2
  "$bin_dir/mocap_launch" "$root/launch_yaml/mobile_mocap_demo.yaml" --duration "$duration" \
    "${set_rate[@]}" --set viewer.port=0 >"$work/demo_$rate.log" 2>&1
  add_row "one process (mobile_mocap_demo.yaml)" "$camera" "$work/demo_$rate.log" \
    "pointers in-process; runs the overlay too"

  echo "camera $camera: one process (tracking.yaml's components) ..." >&2
  "$bin_dir/mocap_launch" "$merged" --duration "$duration" "${set_rate[@]}" "${servos[@]}" \
    >"$work/one_$rate.log" 2>&1
  add_row "one process (tracking.yaml in one group)" "$camera" "$work/one_$rate.log" \
    "pointers in-process"

  echo "camera $camera: four processes on one host ..." >&2
  "$bin_dir/mocap_launch" "$root/launch_yaml/distributed/tracking.yaml" \
    --duration "$duration" "${set_rate[@]}" "${servos[@]}" >"$work/processes_$rate.log" 2>&1
  add_row "4 processes, 1 host (tracking.yaml)" "$camera" "$work/processes_$rate.log" \
    "UDP over loopback"

  echo "camera $camera: four hosts in network namespaces ..." >&2
  name="4 hosts: network namespaces, bridge"
  if [ "$(id -u)" -eq 0 ]; then
    MOCAP_LAUNCH_ARGS="--set camera.rate_hz=$rate" "$root/scripts/netns_scenario.sh" \
      --measure "$duration" --logs "$work/netns_$rate" >"$work/netns_$rate.out" 2>&1
    if grep -q '^phase measure: PASS' "$work/netns_$rate.out"; then
      add_row "$name" "$camera" "$work/netns_$rate/measure.log" \
        "UDP via veth + bridge, 2 hops; evaluator started after the check"
    else
      rows+=("| $name | $camera | - | - | - | - | - | failed: $(grep -m1 -E '^(phase .*FAIL|netns_scenario: cannot)' "$work/netns_$rate.out") |")
    fi
  else
    rows+=("| $name | $camera | - | - | - | - | - | skipped: needs root |")
  fi
done

echo
echo "| deployment | camera | poses/s (median of 1 s windows) | latency median, ms | latency p99, ms | tracked | frames | path |"
echo "|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
echo
echo "Latency: the pose's arrival at the evaluator minus its image's capture stamp. 1280x720" \
  "synthetic camera, the demo scene (two boards); the robot's components run in every" \
  "deployment but the demo's. DDS: ${MOCAP_DDS_IMPLEMENTATION:-fastdds} (MOCAP_DDS_IMPLEMENTATION)." \
  "$(nproc) CPU(s), $(uname -r)."
