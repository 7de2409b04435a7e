#!/usr/bin/env bash
# Sets everything up and runs the follower demo (launch_yaml/follower_demo.yaml) for 40 s: the
# tracking pipeline on a camera carried by a pan/tilt turret on a mobile base, following a
# person with a board. Builds only what the demo runs (mocap_launch and the plugins its launch
# file names), not the other plugins, tests and benchmarks. Extra arguments go to mocap_launch:
# --duration 0 runs until Ctrl-C.
# Watch it live at http://localhost:8765/ (the built-in viewer), or from Foxglove/Lichtblick.
set -euo pipefail
cd "$(dirname "$0")/.."
# What building and running need, nothing else (no test tools, no Docker); a fresh build/
# leaves the tests and benchmarks out (scripts/test.sh turns them on).
scripts/install_deps.sh build run
[ -f build/build.ninja ] || cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DMOCAP_BUILD_TESTS=OFF -DMOCAP_BUILD_BENCHMARKS=OFF > /dev/null
launch=launch_yaml/follower_demo.yaml
mapfile -t plugins < <(sed -n 's/^ *- plugin: *\([a-z0-9_]*\).*/mocap_plugin_\1/p' "$launch")
cmake --build build --parallel "$(nproc)" --target mocap_launch "${plugins[@]}"
echo "demo: open http://localhost:8765/ to watch (or ws://localhost:8765 in Foxglove/Lichtblick)"
exec build/bin/mocap_launch "$launch" --duration 40 "$@"
