#!/usr/bin/env bash
# Builds the Debian package in build-package/: the tests' optimisation (RelWithDebInfo, -O2;
# cpack strips the debug information) without tests and benchmarks, then cpack ->
# build-package/mocap-graph_<version>_amd64.deb (Depends computed from the binaries). Not -O3
# (Release): GCC 12 gives false -Wrestrict warnings on std::string there. Install it with: sudo apt install ./build-package/mocap-graph_*_amd64.deb
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-package -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMOCAP_BUILD_TESTS=OFF \
  -DMOCAP_BUILD_BENCHMARKS=OFF "$@" > /dev/null
cmake --build build-package --parallel "$(nproc)"
cd build-package
rm -f mocap-graph_*_amd64.deb
cpack -G DEB > cpack.log 2>&1 || { cat cpack.log; exit 1; }
ls "$PWD"/mocap-graph_*_amd64.deb
