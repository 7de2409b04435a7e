#!/usr/bin/env bash
# The tracking volume's multi-host form on one machine: each of the four cameras on a host of
# its own (camera and fiducial tracker: launch_yaml/volume_demo.yaml's group cam_N) and the
# fusion on a compute host, five network namespaces on a bridge (scripts/netns_hosts.sh), as
# five machines on a switch. Needs root (ip netns).
#
#   sudo scripts/netns_volume.sh [--faults] [--duration S] [--logs DIR]
#
# Phases, each with a verdict line "phase NAME: PASS|FAIL ...":
#   start         all five hosts start; the fusion must hear every camera, and then pose
#                 arrays with poses reach the compute host (scripts/scenario.sh check)
#   kill_cam_1    --faults: cam_1's process is killed (SIGKILL); poses must keep coming from the
#                 other three cameras and the fusion must report cam_1 silent; it is started
#                 again and must be taken back ("camera cam_1 is back"; the time is said)
#   link_cam_2    --faults: cam_2's link goes down for 3 s: poses keep coming, cam_2 reported
#                 silent, and taken back when the link is up again, nothing restarted
#   measure       the compute host's evaluator over the whole run, against the simulator's
#                 truth: its table (tracked, position and orientation error, latency from
#                 capture to the fused pose), after the run's --duration (default 20 s)
# then "traffic: ..." (bytes through each host's link) and "result: PASS|FAIL ...".
#
# Options:
#   --faults        run the fault phases
#   --duration S    seconds the volume runs before it is measured (default 20)
#   --logs DIR      keep every host's log in DIR (default: shown on failure, then removed)
# MOCAP_DOMAIN_ID is passed on (default 0).
set -uo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin_dir="${MOCAP_BIN_DIR:-$root/build/bin}"
launch_file="$root/launch_yaml/volume_demo.yaml"

faults=0 duration_s=20 logs_out=""
usage() {
  sed -n '2,26p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --faults) faults=1; shift ;;
    --duration) duration_s="${2:?}"; shift 2 ;;
    --logs) logs_out="${2:?}"; shift 2 ;;
    -h | --help) usage ;;
    *) echo "netns_volume.sh: unknown option $1" >&2; usage ;;
  esac
done

hosts=(cam_0 cam_1 cam_2 cam_3 compute)
declare -A address=([cam_0]=10.78.0.1 [cam_1]=10.78.0.2 [cam_2]=10.78.0.3 [cam_3]=10.78.0.4
  [compute]=10.78.0.10)
say() { echo "netns_volume: $*"; }

# shellcheck source=scripts/netns_hosts.sh
source "$root/scripts/netns_hosts.sh"
export MOCAP_DOMAIN_ID="${MOCAP_DOMAIN_ID:-0}"
start_ns=$(date +%s%N)

start() {
  local h="$1" extra=()
  [ "$h" = compute ] && extra=(--set "evaluator.summary_file=$run_dir/summary.yaml"
    --set viewer.port=0)
  on "$h" "$bin_dir/mocap_launch" "$launch_file" --group "$h" "${extra[@]}" \
    >>"$run_dir/$h.log" 2>&1 &
  pid[$h]=$!
}

# One check of pose arrays on the compute host; sets check_line, returns its status.
check_line=""
check() {
  local out="$run_dir/check.out"
  run on compute env MOCAP_BIN_DIR="$bin_dir" "$root/scripts/scenario.sh" check "$@" >"$out" 2>&1
  local code=$?
  check_line="$(grep -m1 '^check: ' "$out" || tail -n 1 "$out")"
  return $code
}

# Waits at most S seconds for the compute log to hold TEXT; prints how long it took (seconds
# since $2, a `date +%s%N`), or returns 1.
wait_for_log() {  # TEXT SINCE_NS TIMEOUT_S
  local deadline=$((SECONDS + $3)) line
  while :; do
    line="$(grep -m1 -F "$1" "$run_dir/compute.log")"
    if [ -n "$line" ]; then
      awk -v a="$2" -v b="$(date +%s%N)" 'BEGIN { printf "%.2f", (b - a) / 1e9 }'
      return 0
    fi
    [ $SECONDS -lt $deadline ] || return 1
    run sleep 0.05
  done
}

verdict() {  # NAME PASS|FAIL TEXT...
  echo "phase $1: $2 ${*:3}"
  if [ "$2" = PASS ]; then passed=$((passed + 1)); else failed=$((failed + 1)); fi
}

# --- start: every camera heard, then (the bodies found: a pose array of the first frames may
# be empty) pose arrays with poses on the compute host.
for h in compute cam_0 cam_1 cam_2 cam_3; do start "$h"; done
missing=""
for c in cam_0 cam_1 cam_2 cam_3; do
  wait_for_log "camera $c: first fiducials" "$start_ns" 30 >/dev/null || missing+="$c "
done
if [ -n "$missing" ]; then
  verdict start FAIL "never heard: $missing"
else
  run sleep 2
  if check --timeout 30 --count 30; then
    verdict start PASS "every camera heard; $check_line"
  else
    verdict start FAIL "every camera heard; $check_line"
  fi
fi

if [ $faults -eq 1 ]; then
  # --- kill_cam_1: a crash, then a fresh start.
  kill -KILL "${pid[cam_1]}" 2>/dev/null
  wait "${pid[cam_1]}" 2>/dev/null
  killed_ns=$(date +%s%N)
  echo "--- killed (SIGKILL), started again by netns_volume ---" >>"$run_dir/cam_1.log"
  if ! silent_s="$(wait_for_log "camera cam_1 is silent" "$killed_ns" 5)"; then
    verdict kill_cam_1 FAIL "cam_1 killed, but the fusion did not report it silent"
  elif ! check --timeout 10 --count 30; then
    verdict kill_cam_1 FAIL "cam_1 killed: poses stopped ($check_line)"
  else
    during="reported silent after ${silent_s} s, poses kept coming ($check_line)"
    restarted_ns=$(date +%s%N)
    start cam_1
    if back_s="$(wait_for_log "camera cam_1 is back" "$restarted_ns" 20)"; then
      verdict kill_cam_1 PASS "cam_1 killed (SIGKILL): $during; started again, taken back" \
        "${back_s} s after its start"
    else
      verdict kill_cam_1 FAIL "cam_1 killed: $during; started again, never taken back"
    fi
  fi

  # --- link_cam_2: the link goes down for 3 s and comes back; nothing restarts.
  n="$(ns cam_2)"
  ip -n "$n" link set eth0 down
  down_ns=$(date +%s%N)
  if silent_s="$(wait_for_log "camera cam_2 is silent" "$down_ns" 5)" &&
    check --timeout 10 --count 30; then
    during="reported silent after ${silent_s} s, poses kept coming ($check_line)"
    ok=1
  else
    during="silent not reported or poses stopped ($check_line)"
    ok=0
  fi
  run sleep 1
  ip -n "$n" link set eth0 up
  ip -n "$n" route replace 224.0.0.0/4 dev eth0
  up_ns=$(date +%s%N)
  if [ $ok -eq 1 ] && back_s="$(wait_for_log "camera cam_2 is back" "$up_ns" 20)"; then
    verdict link_cam_2 PASS "cam_2's link down: $during; up again, taken back ${back_s} s later"
  else
    verdict link_cam_2 FAIL "cam_2's link down: $during"
  fi
fi

# --- measure: the run so far, through the evaluator's summary when compute stops.
elapsed_s=$((($(date +%s%N) - start_ns) / 1000000000))
[ "$elapsed_s" -lt "$duration_s" ] && run sleep $((duration_s - elapsed_s))
kill -TERM "${pid[compute]}" 2>/dev/null
wait "${pid[compute]}" 2>/dev/null
table="$(grep -A1 '| frames |' "$run_dir/compute.log" | sed 's/^.*\]: //')"
if [ -n "$table" ]; then
  verdict measure PASS "the compute host's evaluator over the run:"
  while IFS= read -r line; do echo "measure: $line"; done <<<"$table"
  grep -F "frames fused" "$run_dir/compute.log" | sed 's/^.*\]: /measure: /'
else
  verdict measure FAIL "no table from the evaluator: $(tail -n 3 "$run_dir/compute.log" | tr '\n' ' ')"
fi
finish
