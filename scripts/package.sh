#!/usr/bin/env bash
# Builds the Debian packages in build-package/ (cmake/Package.cmake): mocap-graph (tools,
# plugins, launch files), mocap-graph-camera (camera_source, mocap_calibrate) and
# mocap-graph-dev (headers, find_package), each with Depends computed from its binaries. The
# tests' optimisation (RelWithDebInfo, -O2; cpack strips the debug information), no tests or
# benchmarks. Not -O3 (Release): GCC 12 gives false -Wrestrict warnings on std::string there.
#
#   scripts/package.sh [--runtime-only] [CMAKE ARGUMENTS...]
#
# --runtime-only: compiles what mocap-graph holds and makes that package alone (the container
# image's build stage). Install with: sudo apt install ./build-package/mocap-graph_*_amd64.deb
# MOCAP_PACKAGE_DIR: another build folder than build-package/ (scripts/docker_test.sh builds
# the image's package in a fresh one).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${MOCAP_PACKAGE_DIR:-build-package}
target=all
components=()
if [ "${1:-}" = "--runtime-only" ]; then
  shift
  target=mocap_runtime_package
  components=(-D CPACK_COMPONENTS_ALL=runtime)
fi
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMOCAP_BUILD_TESTS=OFF \
  -DMOCAP_BUILD_BENCHMARKS=OFF "$@" > /dev/null
cmake --build "$dir" --parallel "$(nproc)" --target "$target"
cd "$dir"
rm -f mocap-graph*_amd64.deb
cpack -G DEB "${components[@]}" > cpack.log 2>&1 || { cat cpack.log; exit 1; }
ls "$PWD"/mocap-graph*_amd64.deb
