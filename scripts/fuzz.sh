#!/usr/bin/env bash
# Runs every fuzzer of fuzz/ for SECONDS of processor time each (default 60), two at a time,
# under AddressSanitizer and UndefinedBehaviorSanitizer, and prints a table: executions,
# coverage (libFuzzer's edges "cov" and features "ft"), corpus size and the verdict.
#
#   scripts/fuzz.sh [--no-build] [SECONDS] [NAME...]
#
# Processor time, not time on the clock: a fuzzer that shares the machine (CI runs them beside
# its soak and container test) goes as deep as one alone; on a quiet machine the two are the
# same. When a fuzzer has had its SECONDS it is asked to stop (SIGUSR1: libFuzzer finishes
# the input at hand and prints its statistics).
#
# The fuzzers come from build-asan/ (scripts/sanitize.sh address builds it; this script builds
# just the fuzzers, or the tree if it is missing, unless --no-build says they are built). Each
# starts from its seed corpus, fuzz/corpus/NAME/, and the inputs that once broke it,
# fuzz/regressions/NAME/, and the corpus it grew in earlier runs on this machine:
# MOCAP_CACHE_DIR/fuzz/NAME/ (default /var/cache/mocap-graph/fuzz, or build-asan/fuzz/work when
# that cannot be made), outside the clone, so that each run goes deeper instead of starting
# over; nothing found goes into the repository. An input that crashes, leaks, hangs (over 10 s)
# or runs out of memory (over 2 GB) is kept in build-asan/fuzz/found/NAME/ and fails the run:
# reproduce it with `build-asan/fuzz/fuzz_NAME FILE`, fix it, and keep the file in
# fuzz/regressions/NAME/ (ctest replays it in every build).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=60
build_fuzzers=true
if [ "${1:-}" = --no-build ]; then
  build_fuzzers=false
  shift
fi
if [ $# -gt 0 ] && [[ "$1" =~ ^[0-9]+$ ]]; then
  seconds=$1
  shift
fi
build=build-asan
source scripts/sanitizer_env.sh

if $build_fuzzers && [ ! -f "$build/CMakeCache.txt" ]; then
  scripts/sanitize.sh address --build-only
elif $build_fuzzers; then
  cmake --build "$build" --parallel "$(nproc)" --target mocap_fuzzers
fi

names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for fuzzer in "$build"/fuzz/fuzz_*; do
    names+=("$(basename "$fuzzer" | sed 's/^fuzz_//')")
  done
fi
for name in "${names[@]}"; do
  if [ ! -x "$build/fuzz/fuzz_$name" ]; then
    echo "fuzz.sh: no fuzzer '$name' (fuzz/fuzz_$name.cpp)" >&2
    exit 2
  fi
done

run_one() {
  local name=$1 seconds=$2 build=$3
  local work=$corpus_root/$name found=$build/fuzz/found/$name log=$build/fuzz/logs/$name.log
  mkdir -p "$work" "$found" "$(dirname "$log")"
  local inputs=(fuzz/corpus/"$name")
  [ -d fuzz/regressions/"$name" ] && inputs+=(fuzz/regressions/"$name")
  local start=$SECONDS budget ticks scratch
  budget=$((seconds * $(getconf CLK_TCK)))
  # A temporary directory of its own, removed here: libFuzzer's stop on SIGUSR1 ends the
  # process without its exit handlers, which remove the files a harness writes.
  scratch=$(mktemp -d "/tmp/fuzz_$name.XXXXXX")
  TMPDIR=$scratch "$build/fuzz/fuzz_$name" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$found/" "$work" "${inputs[@]}" > "$log" 2>&1 &
  local pid=$!
  # Its user and system time: fields 14 and 15 of /proc/PID/stat (12 and 13 after the name),
  # until it has had its budget or has ended (state Z until waited for).
  while ticks=$(awk '{ sub(/^.*\) /, ""); if ($1 != "Z") print $12 + $13 }' "/proc/$pid/stat" \
    2> /dev/null) && [ -n "$ticks" ] && [ "$ticks" -lt "$budget" ]; do
    sleep 0.5
  done
  kill -USR1 "$pid" 2> /dev/null
  local status=0
  wait "$pid" || status=$?
  rm -rf "$scratch"
  echo $status > "$log.status"
  echo $((SECONDS - start)) > "$log.wall"
}
corpus_root=${MOCAP_CACHE_DIR:-/var/cache/mocap-graph}/fuzz
mkdir -p "$corpus_root" 2> /dev/null && [ -w "$corpus_root" ] || corpus_root=$build/fuzz/work
export corpus_root
export -f run_one
printf '%s\n' "${names[@]}" | xargs -P "$(nproc)" -I{} bash -c "run_one {} $seconds $build"

failed=0
echo
echo "| fuzzer | processor s | clock s | executions | exec per processor s | cov (edges) | ft (features) | corpus | verdict |"
echo "|---|---|---|---|---|---|---|---|---|"
for name in "${names[@]}"; do
  log=$build/fuzz/logs/$name.log
  status=$(cat "$log.status")
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$([ -z "$executions" ] || echo $((executions / seconds)))
  # The last status line ("#N DONE cov: C ft: F corp: K/...") or, after a crash, the last one
  # printed before it.
  last=$(grep -E '^#[0-9]+.*cov: ' "$log" | tail -1 || true)  # none: it failed at once
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<< "$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<< "$last")
  corpus=$(sed -n 's/.* corp: \([0-9]*\)\/.*/\1/p' <<< "$last")
  verdict=PASS
  if [ "$status" != 0 ] || ls "$build/fuzz/found/$name"/* > /dev/null 2>&1; then
    verdict="FAIL (exit $status, see $log)"
    failed=1
  fi
  echo "| $name | $seconds | $(cat "$log.wall") | ${executions:-?} | ${rate:-?} | ${cov:-?} | ${ft:-?} | ${corpus:-?} | $verdict |"
done
if [ $failed -ne 0 ]; then
  for name in "${names[@]}"; do
    log=$build/fuzz/logs/$name.log
    if [ "$(cat "$log.status")" != 0 ]; then
      echo
      echo "== $name: $(ls "$build/fuzz/found/$name" | head -3 | tr '\n' ' ')"
      grep -E -A25 '^==[0-9]+==ERROR|runtime error|deadly signal|Timeout|out-of-memory|uncaught' "$log" | head -60
    fi
  done
  exit 1
fi
