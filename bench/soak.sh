#!/usr/bin/env bash
# A long run of the follower demo (launch_yaml/follower_demo.yaml: camera at 30 Hz, tracking,
# turret, drive, base, monitor, viewer bridge) with `mocap_bag record` taking its poses,
# fiducials, joint states, velocities and base poses in another process. Every few seconds it
# samples, for both processes, resident memory, open file descriptors and threads, and the
# shared memory both map from /dev/shm (Fast DDS's segments). Prints the trend (first sample
# after the warm-up, each quarter, the last) and what was lost: samples the runtime dropped
# (its "dropped" warnings) and messages the recorder dropped, beside the pose arrays in the bag.
# With --check it exits non-zero when a bound is passed:
#   growth after the warm-up: RSS 16 MB per process, 4 file descriptors, 2 threads, /dev/shm
#   4 MB; nothing dropped or missing; both processes end with status 0.
#
#   bench/soak.sh [--minutes M] [--check]    (default 30 minutes)
set -uo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin_dir="${MOCAP_BIN_DIR:-$root/build/bin}"
minutes=30
check=false
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) minutes="${2:?}"; shift 2 ;;
    --check) check=true; shift ;;
    -h | --help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "soak.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
duration=$(awk -v m="$minutes" 'BEGIN { printf "%d", m * 60 }')
[ "$duration" -ge 60 ] || { echo "soak.sh: --minutes must be at least 1" >&2; exit 2; }
interval=$(( duration >= 600 ? 10 : 2 ))
warmup=$(( duration >= 600 ? 60 : 20 ))

work="$(mktemp -d /tmp/soak.XXXXXX)"
demo_pid="" recorder_pid=""
cleanup() {
  [ -n "$recorder_pid" ] && kill "$recorder_pid" 2>/dev/null
  [ -n "$demo_pid" ] && kill "$demo_pid" 2>/dev/null
  wait 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
export MOCAP_DOMAIN_ID="${MOCAP_DOMAIN_ID:-$((100 + $$ % 30))}"

topics=(/mocap/poses /mocap/fiducials /turret/joint_states /cmd_vel /base/pose)
"$bin_dir/mocap_bag" record -o "$work/bag" "${topics[@]}" > "$work/recorder.log" 2>&1 &
recorder_pid=$!
"$bin_dir/mocap_launch" "$root/launch_yaml/follower_demo.yaml" --duration "$duration" \
  --set servos.device_link="$work/servos" --set turret.port="$work/servos" \
  --set viewer.port=0 > "$work/demo.log" 2>&1 &
demo_pid=$!

# The shared memory the demo and the recorder map (Fast DDS's segments and port queues), in
# kB: theirs alone, not what other programs on the machine hold (CI runs the container test,
# with DDS participants of its own on this machine, beside the soak).
shm_kb() {
  cat "/proc/$demo_pid/maps" "/proc/$recorder_pid/maps" 2>/dev/null |
    grep -o '/dev/shm/[^ ]*$' | sort -u | xargs -r du -ck 2>/dev/null |
    awk '/\ttotal$/ { total = $1 } END { print total + 0 }'
}
sample() {  # PID -> "rss_kb fds threads"
  local rss threads fds
  rss=$(awk '/^VmRSS/ { print $2 }' "/proc/$1/status" 2>/dev/null)
  threads=$(awk '/^Threads/ { print $2 }' "/proc/$1/status" 2>/dev/null)
  fds=$(ls "/proc/$1/fd" 2>/dev/null | wc -l)
  echo "${rss:-0} $fds ${threads:-0}"
}

samples=()  # "seconds demo_rss demo_fds demo_threads rec_rss rec_fds rec_threads shm_kb"
start=$(date +%s)
while kill -0 "$demo_pid" 2>/dev/null; do
  sleep "$interval"
  now=$(( $(date +%s) - start ))
  kill -0 "$demo_pid" 2>/dev/null || break
  [ "$now" -ge "$warmup" ] || continue
  samples+=("$now $(sample "$demo_pid") $(sample "$recorder_pid") $(shm_kb)")
done
wait "$demo_pid"
demo_status=$?
demo_pid=""
kill -INT "$recorder_pid" 2>/dev/null
wait "$recorder_pid"
recorder_status=$?
recorder_pid=""

[ "${#samples[@]}" -ge 2 ] || { echo "soak.sh: too few samples" >&2; cat "$work/demo.log" >&2; exit 1; }
echo "| time | demo RSS MB | demo fds | demo threads | recorder RSS MB | recorder fds | recorder threads | /dev/shm MB |"
echo "|---|---|---|---|---|---|---|---|"
n=${#samples[@]}
for i in 0 $((n / 4)) $((n / 2)) $((3 * n / 4)) $((n - 1)); do
  echo "${samples[$i]}" | awk '{ printf "| %d s | %.1f | %d | %d | %.1f | %d | %d | %.1f |\n", $1, $2 / 1024, $3, $4, $5 / 1024, $6, $7, $8 / 1024 }'
done | uniq

read -r _ d_rss0 d_fd0 d_th0 r_rss0 r_fd0 r_th0 shm0 <<< "${samples[0]}"
read -r _ d_rss1 d_fd1 d_th1 r_rss1 r_fd1 r_th1 shm1 <<< "${samples[$((n - 1))]}"
# The largest value after the warm-up, against the first: growth, not noise at the end.
max_of() { printf '%s\n' "${samples[@]}" | awk -v c="$1" 'BEGIN { m = 0 } { if ($c > m) m = $c } END { print m }'; }
growth() { echo $(( $(max_of "$1") - $2 )); }
g_d_rss=$(growth 2 "$d_rss0"); g_d_fd=$(growth 3 "$d_fd0"); g_d_th=$(growth 4 "$d_th0")
g_r_rss=$(growth 5 "$r_rss0"); g_r_fd=$(growth 6 "$r_fd0"); g_r_th=$(growth 7 "$r_th0")
g_shm=$(growth 8 "$shm0")

drop_lines=' [1-9][0-9]* (sample\(s\) )?dropped \('  # "0 dropped (0 in all)" is not one
dropped=$(grep -cE "$drop_lines" "$work/demo.log")
recorded_line=$(grep "^recorded " "$work/recorder.log" | tail -n 1)
recorder_dropped=$(echo "$recorded_line" | sed -n 's/.*; \([0-9]*\) dropped.*/\1/p')
poses_in_bag=$("$bin_dir/mocap_bag" info "$work/bag" 2>/dev/null |
  sed -n 's|.*Topic: /mocap/poses .*Count: \([0-9]*\).*|\1|p')
poses_rate=$(sed -n 's/.*rates over the run: camera [0-9.]* Hz, poses \([0-9.]*\) Hz.*/\1/p' "$work/demo.log")
echo
echo "growth after the first ${warmup} s (largest sample - first): demo RSS $((g_d_rss / 1024)) MB, fds $g_d_fd, threads $g_d_th; recorder RSS $((g_r_rss / 1024)) MB, fds $g_r_fd, threads $g_r_th; /dev/shm $((g_shm / 1024)) MB"
echo "lost: ${dropped} runtime drop warning(s), ${recorder_dropped:-0} dropped by the recorder; ${poses_in_bag:-?} pose arrays in the bag (poses at ${poses_rate:-?} Hz over the run)"
echo "recorder: ${recorded_line:-no closing line}; exit status: demo $demo_status, recorder $recorder_status"
[ "$dropped" -gt 0 ] && grep -E "$drop_lines" "$work/demo.log" | sed 's/^/  /' | head -n 5

if $check; then
  failed=0
  bound() {  # NAME VALUE LIMIT
    if [ "$2" -gt "$3" ]; then echo "FAIL $1: $2 > $3"; failed=1; fi
  }
  bound "demo RSS growth (kB)" "$g_d_rss" 16384
  bound "recorder RSS growth (kB)" "$g_r_rss" 16384
  bound "demo fd growth" "$g_d_fd" 4
  bound "recorder fd growth" "$g_r_fd" 4
  bound "demo thread growth" "$g_d_th" 2
  bound "recorder thread growth" "$g_r_th" 2
  bound "/dev/shm growth (kB)" "$g_shm" 4096
  bound "runtime drop warnings" "$dropped" 0
  bound "recorder drops" "${recorder_dropped:-0}" 0
  [ -n "$recorded_line" ] || { echo "FAIL the recorder printed no closing line"; failed=1; }
  [ "$demo_status" -eq 0 ] || { echo "FAIL demo exit status $demo_status"; failed=1; }
  [ "$recorder_status" -eq 0 ] || { echo "FAIL recorder exit status $recorder_status"; failed=1; }
  [ "$failed" -eq 0 ] && echo "PASS every bound held"
  exit "$failed"
fi
