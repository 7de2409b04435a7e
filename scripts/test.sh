#!/usr/bin/env bash
# Sets everything up, builds with warnings as errors, checks formatting and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh -DMOCAP_WERROR=ON -DMOCAP_BUILD_TESTS=ON -DMOCAP_BUILD_BENCHMARKS=ON
scripts/check_format.sh
# The tests' independent clients and readers (pinned in test/package-lock.json).
npm ci --prefix test --no-audit --no-fund --loglevel=error
cd build
ctest --output-on-failure --parallel "$(nproc)"
