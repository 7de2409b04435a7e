#!/usr/bin/env bash
# The multi-host tracking scenario on one machine: four network namespaces (sensor, compute,
# robot, observer) joined by a Linux bridge in a fifth, each running its share with
# scripts/scenario.sh, as four hosts on a switch would. Needs root (ip netns).
#
#   sudo scripts/netns_scenario.sh [--faults] [--keep-going] [options]
#
# Phases, each with a verdict line "phase NAME: PASS|FAIL ...":
#   start         all four hosts start; poses must reach the observer (scenario.sh check)
#                 and the robot must follow the board
#   kill_HOST     --faults: HOST's process is killed (SIGKILL); poses must stop reaching the
#                 observer host (sensor, compute) or keep coming (robot, observer: the check
#                 is not the observer's evaluator); it is started again and poses must reach
#                 the observer again, the other hosts untouched
#   link_HOST     --faults: HOST's network link goes down for --down seconds (longer than
#                 the DDS lease, so peers forget each other); poses must stop (keep coming if
#                 HOST is the robot, which only listens); the link comes back and poses must
#                 reach the observer again, no process restarted
# Each phase also wants every other host still running, the robot following the board and the
# observer's evaluator evaluating poses (their logs' last word on it).
#   measure       --measure S: a fresh pose evaluator on the observer host for S seconds;
#                 its final table (rate, tracked %, latency from image capture to arrival)
# then "traffic: ..." (bytes through each host's link) and "result: PASS|FAIL ...".
#
# Options:
#   --faults            run the fault phases
#   --keep-going        go on after a failed phase (default: stop at the first)
#   --kill HOST         the host killed and restarted (default: compute)
#   --link HOST         the host whose link goes down and up (default: compute)
#   --down S            seconds the link stays down (default: 7)
#   --check-timeout S   the longest a check waits for poses (default: 30)
#   --measure S         measure for S seconds at the end
#   --logs DIR          keep every host's log in DIR (default: shown on failure, then removed)
#
# Everything it makes is named mgtest_<pid>_*, so runs side by side do not clash, and is
# removed when it ends, however it ends (the addresses 10.77.0.1-4/24 live only inside these
# namespaces). MOCAP_DOMAIN_ID is passed on (default 0).
set -uo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
scenario="$root/scripts/scenario.sh"

faults=0 keep_going=0 kill_host=compute link_host=compute down_s=7 check_timeout=30
measure_s=0 logs_out=""
usage() {
  sed -n '2,37p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --faults) faults=1; shift ;;
    --keep-going) keep_going=1; shift ;;
    --kill) kill_host="${2:?}"; shift 2 ;;
    --link) link_host="${2:?}"; shift 2 ;;
    --down) down_s="${2:?}"; shift 2 ;;
    --check-timeout) check_timeout="${2:?}"; shift 2 ;;
    --measure) measure_s="${2:?}"; shift 2 ;;
    --logs) logs_out="${2:?}"; shift 2 ;;
    -h | --help) usage ;;
    *) echo "netns_scenario.sh: unknown option $1" >&2; usage ;;
  esac
done

hosts=(sensor compute robot observer)
declare -A address=([sensor]=10.77.0.1 [compute]=10.77.0.2 [robot]=10.77.0.3 [observer]=10.77.0.4)
for h in "$kill_host" "$link_host"; do
  [ -n "${address[$h]:-}" ] || { echo "netns_scenario.sh: no host '$h' (${hosts[*]})" >&2; exit 2; }
done

say() { echo "netns_scenario: $*"; }

# shellcheck source=scripts/netns_hosts.sh
source "$root/scripts/netns_hosts.sh"

export MOCAP_DOMAIN_ID="${MOCAP_DOMAIN_ID:-0}"
export MOCAP_SERVO_LINK="$run_dir/servos"

start() {
  local h="$1"
  on "$h" "$scenario" "$h" >>"$run_dir/$h.log" 2>&1 &
  pid[$h]=$!
}

# One check on the observer host; sets check_line, returns its status.
check_line=""
check() {
  local out="$run_dir/check.out"
  run on observer "$scenario" check "$@" >"$out" 2>&1
  local code=$?
  check_line="$(grep -m1 '^check: ' "$out" || tail -n 1 "$out")"
  return $code
}

# The hosts other than $1 that are no longer running (empty: all are).
stopped_others() {
  local h out=""
  for h in "${hosts[@]}"; do
    [ "$h" = "$1" ] && continue
    alive "$h" || out+="$h "
  done
  echo "${out% }"
}

# True once the last line of HOST's log that matches SELECT matches WANT too (waits 10 s).
log_says() {  # HOST SELECT WANT
  local deadline=$((SECONDS + 10)) last
  while :; do
    last="$(grep -E "$2" "$run_dir/$1.log" | tail -n 1)"
    if grep -qE "$3" <<<"$last"; then return 0; fi
    [ $SECONDS -lt $deadline ] || return 1
    run sleep 0.5
  done
}

# The verdict of a phase whose check passed: FAIL if a host other than $2 stopped, the robot
# does not follow the board again or the observer's evaluator does not evaluate poses again.
settle() {  # PHASE HOST_EXEMPT TEXT
  local gone
  gone="$(stopped_others "$2")"
  if [ -n "$gone" ]; then
    verdict "$1" FAIL "$3; stopped: $gone"
  elif ! log_says robot 'track of [A-Za-z0-9_]+ [a-z]+: ' ': following'; then
    verdict "$1" FAIL "$3; but the robot does not follow the board"
  elif ! log_says observer '\[evaluator\]: ' ' frames/s, latency '; then
    verdict "$1" FAIL "$3; but the observer's evaluator evaluates no poses"
  else
    verdict "$1" PASS "$3; robot following, observer evaluating"
  fi
}

verdict() {  # NAME PASS|FAIL TEXT...
  echo "phase $1: $2 ${*:3}"
  if [ "$2" = PASS ]; then passed=$((passed + 1)); else failed=$((failed + 1)); fi
  if [ "$2" = FAIL ] && [ $keep_going -eq 0 ]; then finish; fi
}

# --- start: every host; poses must reach the observer.
for h in observer robot compute sensor; do start "$h"; done
observer_rx_before="$(link_bytes observer rx)"
if check --timeout "$check_timeout"; then
  received=$(($(link_bytes observer rx) - observer_rx_before))
  settle start none "$check_line; observer link received $((received / 1024)) KiB"
else
  verdict start FAIL "$check_line"
fi

# While a fault lasts, poses must stop reaching the observer host when the fault cuts the
# pipeline or the observer host off ("stop": the fault is real), and keep coming when it does
# not ("flow": the robot only listens; the observer host's check is not its evaluator).
during_ok=0 during_text=""
during_fault() {  # stop|flow
  if [ "$1" = stop ]; then
    if check --timeout 3 --count 5; then
      during_ok=0 during_text="poses still arrived ($check_line)"
    else
      during_ok=1 during_text="no poses meanwhile"
    fi
  elif check --timeout 10 --count 5; then
    during_ok=1 during_text="poses kept coming meanwhile"
  else
    during_ok=0 during_text="poses stopped, though they need not ($check_line)"
  fi
}

if [ $faults -eq 1 ]; then
  # --- kill_HOST: SIGKILL (a crash: no goodbye to the peers), then a fresh start.
  h="$kill_host"
  kill -KILL "${pid[$h]}" 2>/dev/null
  wait "${pid[$h]}" 2>/dev/null
  echo "--- killed (SIGKILL), started again by netns_scenario ---" >>"$run_dir/$h.log"
  case "$h" in sensor | compute) during_fault stop ;; *) during_fault flow ;; esac
  start "$h"
  if [ $during_ok -eq 0 ]; then
    verdict "kill_$h" FAIL "killed $h (SIGKILL): $during_text"
  elif check --timeout "$check_timeout"; then
    settle "kill_$h" "$h" "killed $h (SIGKILL), $during_text, restarted it alone; $check_line"
  else
    verdict "kill_$h" FAIL "after the restart: $check_line"
  fi

  # --- link_HOST: the host's link goes down and comes back; nothing restarts.
  h="$link_host"
  n="$(ns "$h")"
  ip -n "$n" link set eth0 down
  t0=$SECONDS
  case "$h" in robot) during_fault flow ;; *) during_fault stop ;; esac
  remaining=$((down_s - (SECONDS - t0)))
  [ $remaining -gt 0 ] && run sleep "$remaining"
  ip -n "$n" link set eth0 up
  # Taking a link down drops its routes; the address's own route comes back by itself.
  ip -n "$n" route replace 224.0.0.0/4 dev eth0
  if [ $during_ok -eq 0 ]; then
    verdict "link_$h" FAIL "$h's link down: $during_text"
  elif check --timeout "$check_timeout"; then
    settle "link_$h" none \
      "$h's link down ${down_s} s, $during_text, up again, no restart; $check_line"
  else
    verdict "link_$h" FAIL "after the link came back: $check_line"
  fi
fi

if [ "$measure_s" != 0 ]; then
  # --- measure: a fresh evaluator on the observer host, steady state only.
  log="$run_dir/measure.log"
  run on observer "$scenario" observer --duration "$measure_s" \
    --set evaluator.summary_file="$run_dir/measure.yaml" >"$log" 2>&1
  table="$(grep -A1 '| frames |' "$log" | sed 's/^.*\]: //')"
  if [ -n "$table" ]; then
    verdict measure PASS "over ${measure_s} s at the observer:"
    while IFS= read -r line; do echo "measure: $line"; done <<<"$table"
    sed 's/^/measure: /' "$run_dir/measure.yaml" 2>/dev/null
  else
    verdict measure FAIL "no table from the evaluator: $(tail -n 3 "$log" | tr '\n' ' ')"
  fi
fi

finish
