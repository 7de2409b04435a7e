#!/usr/bin/env bash
# The README's test command: sets everything up and runs every test once.
#
#   scripts/test.sh [plain] [address]   (both by default)
#
# plain: builds with g++ and warnings as errors what the package, the Docker image, the
#   benchmarks and the soak use, and the tests the sanitizer build cannot run (the parts plain,
#   realtime and busy_cores: test/CMakeLists.txt says which and why; the other tests are
#   configured in build/ but compiled only in the sanitizer build: `cmake --build build --target
#   <test>` builds one here), checks formatting and that every test is in one part, and runs
#   those tests.
# address: every other test under AddressSanitizer and UndefinedBehaviorSanitizer
#   (scripts/sanitize.sh address).
set -euo pipefail
cd "$(dirname "$0")/.."
parts=("$@")
[ ${#parts[@]} -gt 0 ] || parts=(plain address)
scripts/install_deps.sh all
for part in "${parts[@]}"; do
  case "$part" in
    plain)
      scripts/build.sh -DMOCAP_WERROR=ON -DMOCAP_BUILD_TESTS=ON -DMOCAP_BUILD_BENCHMARKS=ON \
        -DMOCAP_BUILD_TESTS_IN_ALL=OFF
      cmake --build build --parallel "$(nproc)" --target mocap_plain_tests
      scripts/check_format.sh
      cmake -DBUILD=build -P scripts/check_test_parts.cmake
      # The tests' independent clients and readers (pinned in test/package-lock.json).
      npm ci --prefix test --no-audit --no-fund --loglevel=error
      # Two at a time (test/CMakeLists.txt); what CI compiles beside them runs in an idle
      # CPU cgroup (.ci/run, scripts/run_idle.sh).
      MOCAP_TEST_PARALLEL=2 scripts/run_tests.sh build "plain, real time" -L '^realtime$'
      # Side by side: the slow-subscriber loads are paced by their subscribers and the package
      # tests wait on dpkg and a compiler; then the loads that keep every core busy, one at a
      # time (the swarm demo in a browser beside a busy-core DDS load: the page starved).
      MOCAP_TEST_PARALLEL=4 scripts/run_tests.sh build plain -L '^plain$'
      MOCAP_TEST_PARALLEL=1 scripts/run_tests.sh build "plain, busy cores" -L '^busy_cores$'
      ;;
    address) scripts/sanitize.sh address ;;
    *)
      echo "usage: scripts/test.sh [plain] [address]" >&2
      exit 2
      ;;
  esac
done
