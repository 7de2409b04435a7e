#!/usr/bin/env bash
# The README's test command: sets everything up and runs every test once.
#
#   scripts/test.sh [plain] [address]   (both by default)
#
# plain: builds with g++ and warnings as errors what the package, the Docker image, the
#   benchmarks and the soak use, and the tests the sanitizer build cannot run (scripts/
#   test_lists.sh says which and why; the other tests are configured in build/ but compiled only
#   in the sanitizer build: `cmake --build build --target <test>` builds one here), checks
#   formatting, and runs those tests.
# address: every other test under AddressSanitizer and UndefinedBehaviorSanitizer
#   (scripts/sanitize.sh address).
set -euo pipefail
cd "$(dirname "$0")/.."
parts=("$@")
[ ${#parts[@]} -gt 0 ] || parts=(plain address)
scripts/install_deps.sh all
source scripts/test_lists.sh
# Pauses (STOP) or resumes (CONT) the process group MOCAP_BACKGROUND_PGID names, if any.
background() {
  [ -z "${MOCAP_BACKGROUND_PGID:-}" ] || kill -"$1" -- "-$MOCAP_BACKGROUND_PGID" 2> /dev/null || true
}
trap 'background CONT' EXIT
for part in "${parts[@]}"; do
  case "$part" in
    plain)
      scripts/build.sh -DMOCAP_WERROR=ON -DMOCAP_BUILD_TESTS=ON -DMOCAP_BUILD_BENCHMARKS=ON \
        -DMOCAP_BUILD_TESTS_IN_ALL=OFF
      cmake --build build --parallel "$(nproc)" --target mocap_plain_tests
      scripts/check_format.sh
      # The tests' independent clients and readers (pinned in test/package-lock.json).
      npm ci --prefix test --no-audit --no-fund --loglevel=error
      # Nothing beside them: what CI runs in the background (.ci/run) is paused meanwhile.
      background STOP
      MOCAP_TEST_PARALLEL=1 scripts/run_tests.sh build "plain, real time" -R "^($realtime_tests)\$"
      background CONT
      # Side by side: the slow-subscriber loads are paced by their subscribers and the package
      # tests wait on dpkg and a compiler; then the loads that keep every core busy.
      MOCAP_TEST_PARALLEL=4 scripts/run_tests.sh build plain -R "^($plain_only_tests)\$" \
        -E "^($realtime_tests|$busy_core_tests)\$"
      scripts/run_tests.sh build "plain, busy cores" -R "^($busy_core_tests)\$"
      ;;
    address) scripts/sanitize.sh address ;;
    *)
      echo "usage: scripts/test.sh [plain] [address]" >&2
      exit 2
      ;;
  esac
done
