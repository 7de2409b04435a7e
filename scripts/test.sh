#!/usr/bin/env bash
# The README's test command: sets everything up and runs every test once.
#
#   scripts/test.sh [plain] [address]   (both by default)
#
# plain: builds everything with g++ and warnings as errors (what the package, the Docker image,
#   the benchmarks and the soak use), checks formatting, and runs the tests the sanitizer build
#   cannot (scripts/test_lists.sh says which and why).
# address: every other test under AddressSanitizer and UndefinedBehaviorSanitizer
#   (scripts/sanitize.sh address).
set -euo pipefail
cd "$(dirname "$0")/.."
parts=("$@")
[ ${#parts[@]} -gt 0 ] || parts=(plain address)
scripts/install_deps.sh all
source scripts/test_lists.sh
for part in "${parts[@]}"; do
  case "$part" in
    plain)
      scripts/build.sh -DMOCAP_WERROR=ON -DMOCAP_BUILD_TESTS=ON -DMOCAP_BUILD_BENCHMARKS=ON
      scripts/check_format.sh
      # The tests' independent clients and readers (pinned in test/package-lock.json).
      npm ci --prefix test --no-audit --no-fund --loglevel=error
      MOCAP_TEST_PARALLEL=1 scripts/run_tests.sh build "plain, real time" -R "^($realtime_tests)\$"
      scripts/run_tests.sh build plain -R "^($plain_only_tests)\$" -E "^($realtime_tests)\$"
      ;;
    address) scripts/sanitize.sh address ;;
    *)
      echo "usage: scripts/test.sh [plain] [address]" >&2
      exit 2
      ;;
  esac
done
