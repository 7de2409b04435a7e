#!/usr/bin/env bash
# The multi-host tracking scenario (launch_yaml/distributed/tracking.yaml), one host's share:
# the same commands run in network namespaces (scripts/netns_scenario.sh), in containers
# (docker/compose.yaml) or on real machines.
#
#   scripts/scenario.sh sensor|compute|robot|observer [MOCAP_LAUNCH ARGUMENTS...]
#       runs that host's group in this process (exec mocap_launch FILE --group ROLE ...);
#       extra arguments go to mocap_launch (--duration S, --set C.P=V)
#   scripts/scenario.sh check [--timeout S] [--count N]
#       waits at most S seconds (default 30) for N pose arrays (default 30) on /mocap/poses,
#       stamped after the check started (host clocks agreeing within 2 s) and holding at least
#       one pose; prints one verdict line, "check: PASS ..." or "check: FAIL ...", and exits 0
#       or 1
#
# Environment:
#   MOCAP_DOMAIN_ID    the DDS domain, as for every tool (default 0)
#   MOCAP_BIN_DIR      where mocap_launch and mocap_topic are (default: build/bin in a
#                      checkout; installed, as share/mocap_graph/scripts/, the prefix's bin/)
#   MOCAP_LAUNCH_FILE  the launch file (default: launch_yaml/distributed/tracking.yaml)
#   MOCAP_SERVO_LINK   robot: the servo simulator's pseudo-terminal link (default: one per
#                      process in /tmp, so robots on one machine do not share it)
#   MOCAP_LAUNCH_ARGS  more mocap_launch arguments for every host, split at spaces
#                      (e.g. "--set camera.rate_hz=60"; a component another host runs is
#                      validated but not started)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
default_bin_dir="$root/build/bin"
[ -d "$default_bin_dir" ] || default_bin_dir="$(cd "$root/../.." && pwd)/bin"
bin_dir="${MOCAP_BIN_DIR:-$default_bin_dir}"
launch_file="${MOCAP_LAUNCH_FILE:-$root/launch_yaml/distributed/tracking.yaml}"

usage() {
  sed -n '2,23p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 2
}

[ $# -ge 1 ] || usage
role="$1"
shift

# Seconds since the epoch with nanoseconds, from the same clock the stamps come from.
now_ns() { date +%s%N; }

check() {
  local timeout=30 count=30
  while [ $# -gt 0 ]; do
    case "$1" in
      --timeout) timeout="${2:?--timeout needs seconds}"; shift 2 ;;
      --count) count="${2:?--count needs a number}"; shift 2 ;;
      *) echo "scenario.sh check: unknown option $1" >&2; exit 2 ;;
    esac
  done
  if ! [[ "$timeout" =~ ^[0-9]+$ && "$count" =~ ^[0-9]+$ && "$timeout" -ge 1 && "$count" -ge 1 ]]; then
    echo "scenario.sh check: --timeout and --count take whole numbers >= 1" >&2
    exit 2
  fi
  local out err started_ns ended_ns deadline_ns left code attempts=0 errors=""
  out="$(mktemp)"
  err="$(mktemp)"
  # shellcheck disable=SC2064
  trap "rm -f '$out' '$err'" EXIT
  # A signal stops the check at once, mocap_topic with it (timeout passes SIGTERM on).
  local echo_pid="" stopping=0
  trap 'stopping=1; [ -z "$echo_pid" ] || kill -TERM "$echo_pid" 2>/dev/null' TERM INT
  started_ns="$(now_ns)"
  deadline_ns=$((started_ns + timeout * 1000000000))
  # mocap_topic waits for a publisher and stops after `count` arrays; at the deadline it gets
  # SIGTERM and leaves cleanly (DDS shared memory included). One that fails early (an error,
  # not the deadline) is started again while time is left.
  while :; do
    attempts=$((attempts + 1))
    left=$(((deadline_ns - $(now_ns) + 999999999) / 1000000000))
    [ "$left" -ge 1 ] || left=1
    timeout --kill-after=5 "$left" "$bin_dir/mocap_topic" echo /mocap/poses --count "$count" \
      >"$out" 2>"$err" &
    echo_pid=$!
    code=0
    wait "$echo_pid" || code=$?
    if [ $stopping -eq 1 ]; then
      wait "$echo_pid" || true
      echo "check: FAIL stopped by a signal before poses arrived"
      exit 143
    fi
    if [ "$code" -eq 0 ] || [ "$code" -eq 124 ] || [ "$code" -eq 137 ]; then break; fi
    errors="$errors${errors:+; }exit $code: $(tail -n 1 "$err")"
    [ $(((deadline_ns - $(now_ns) + 999999999) / 1000000000)) -ge 2 ] || break
    sleep 0.5
  done
  ended_ns="$(now_ns)"
  # Each array: a top-level header stamp (4-space "sec:"/"nanosec:"), then its poses
  # ("  - name:"). Counted: arrays, fresh arrays (stamped after the check began, give or take
  # 2 s of clock difference between hosts: not an old sample), arrays with at least one pose,
  # the names seen and the newest stamp.
  local summary
  summary="$(awk -v started="$((started_ns - 2000000000))" '
    function flush() {
      if (!have) return
      arrays++
      if (stamp >= started) fresh++
      if (poses > 0 && stamp >= started) good++
      if (stamp > newest) newest = stamp
      have = 0
    }
    /^header:/ { flush(); have = 1; poses = 0; next }
    /^    sec: / { sec = $2; next }
    /^    nanosec: / { stamp = sec * 1e9 + $2; next }
    /^  - name: / { poses++; gsub(/"/, "", $3); names[$3] = 1; next }
    END {
      flush()
      list = ""
      for (n in names) list = list (list == "" ? "" : ",") n
      printf "%d %d %d %.0f %s\n", arrays, fresh, good, newest, (list == "" ? "-" : list)
    }' "$out")"
  local arrays fresh good newest names
  read -r arrays fresh good newest names <<<"$summary"
  local elapsed age
  elapsed="$(awk -v a="$started_ns" -v b="$ended_ns" 'BEGIN { printf "%.1f", (b - a) / 1e9 }')"
  if [ "$arrays" -gt 0 ]; then
    age="$(awk -v a="$newest" -v b="$ended_ns" 'BEGIN { printf "%.2f", (b - a) / 1e9 }')"
  fi
  local retried=""
  [ -z "$errors" ] || retried="; $((attempts - 1)) earlier attempt(s) failed ($errors)"
  if [ "$code" -eq 0 ] && [ "$good" -ge "$count" ]; then
    echo "check: PASS $good of $count pose arrays with poses ($names) on /mocap/poses in" \
      "${elapsed} s; newest stamp ${age} s old$retried"
    return 0
  fi
  local why
  if grep -q "waiting for a publisher" "$err" && [ "$arrays" -eq 0 ]; then
    why="no publisher of /mocap/poses found"
  elif [ "$arrays" -eq 0 ]; then
    why="a publisher, but no pose array arrived"
  else
    why="$arrays arrays, $fresh fresh, $good fresh with poses ($names)"
  fi
  [ -z "$errors" ] || why="$why; mocap_topic failed $attempts time(s) ($errors)"
  echo "check: FAIL $why within ${timeout} s (wanted $count)"
  return 1
}

read -r -a launch_args <<<"${MOCAP_LAUNCH_ARGS:-}"
case "$role" in
  sensor | compute | observer)
    exec "$bin_dir/mocap_launch" "$launch_file" --group "$role" "${launch_args[@]}" "$@"
    ;;
  robot)
    link="${MOCAP_SERVO_LINK:-${TMPDIR:-/tmp}/mocap_servos_$$}"
    exec "$bin_dir/mocap_launch" "$launch_file" --group robot \
      --set "servos.device_link=$link" --set "turret.port=$link" "${launch_args[@]}" "$@"
    ;;
  check)
    check "$@"
    ;;
  -h | --help)
    usage
    ;;
  *)
    echo "scenario.sh: unknown role '$role' (sensor, compute, robot, observer, check)" >&2
    exit 2
    ;;
esac
