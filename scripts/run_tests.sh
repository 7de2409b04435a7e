#!/usr/bin/env bash
# Runs ctest in BUILD and accounts for it: how many tests ran, and every skipped test with
# its reason. A skip for missing hardware (no CAN interface here) is allowed; any other skip
# fails the run, as a failed test does.
#
#   scripts/run_tests.sh BUILD PART [CTEST ARGS]      (MOCAP_TEST_PARALLEL: tests at once)
#
# Then the part's slowest tests. One line per run, "PART: N tests run, M skipped", goes to the
# file MOCAP_TEST_SUMMARY names (.ci/run prints them together at the end).
set -euo pipefail
build=$1
part=$2
shift 2
hardware_skip='CAN (sockets|interface)|vcan'

status=0
(cd "$build" && ctest --output-on-failure --no-tests=error --parallel "${MOCAP_TEST_PARALLEL:-$(nproc)}" "$@") | tee "$build/ctest.out" ||
  status=$?
total=$(sed -n 's/^.*tests passed, [0-9]* tests failed out of \([0-9]*\)$/\1/p' "$build/ctest.out" | tail -1)
skipped=$(grep -E '^[[:space:]]*[0-9]+ - .* \(Skipped\)$' "$build/ctest.out" | sed -E 's/^[[:space:]]*[0-9]+ - (.*) \(Skipped\)$/\1/' || true)
count=0
while IFS= read -r name; do
  [ -n "$name" ] || continue
  count=$((count + 1))
  # gtest prints "<file>:<line>: Skipped" and the reason on the next line.
  reason=$(awk -v test="$name" '
    /^[0-9]+\/[0-9]+ Test: / { inside = substr($0, index($0, "Test: ") + 6) == test; next }
    inside && /: Skipped$/ { getline; print; exit }' "$build/Testing/Temporary/LastTest.log")
  if [[ "$reason" =~ $hardware_skip ]]; then
    line="$part: skipped $name (missing hardware: $reason)"
  else
    line="$part: skipped $name: ${reason:-no reason given} -- only missing hardware may skip"
    status=1
  fi
  echo "$line" >&2
  [ -z "${MOCAP_TEST_SUMMARY:-}" ] || echo "$line" >> "$MOCAP_TEST_SUMMARY"
done <<< "$skipped"
# Where the part's time went: its slowest tests.
echo "$part: slowest tests (s):"
awk '/^[0-9]+\/[0-9]+ Testing: / { name = $3 } /^Test time = / { print $4, name }' \
  "$build/Testing/Temporary/LastTest.log" | sort -rn | awk 'NR <= 8 { print "  " $0 }'
# ctest counts a skipped test among the passed ones.
line="$part: $((${total:-0} - count)) tests run, $count skipped"
echo "$line"
[ -z "${MOCAP_TEST_SUMMARY:-}" ] || echo "$line" >> "$MOCAP_TEST_SUMMARY"
exit $status
