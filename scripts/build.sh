#!/usr/bin/env bash
# Configures and builds mocap-graph in build/ (executables in build/bin, plugins in
# build/lib/mocap_graph/plugins).
# Extra arguments go to cmake, e.g. -DMOCAP_WERROR=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" > /dev/null
cmake --build build --parallel "$(nproc)"
