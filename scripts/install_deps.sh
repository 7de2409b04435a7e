#!/usr/bin/env bash
# Installs the Debian 12 packages mocap-graph needs: the one list. Safe to run again: when
# everything is installed it changes nothing, and it reads the package index only when a
# package is missing.
#
#   scripts/install_deps.sh [GROUP...]   GROUP: build, run, package, test or all (the default)
#
# build: compiling the product; run: its tools at run time; package: the Debian packages;
# test: the tests, sanitizers, fuzzers, benchmarks and the container test. scripts/demo.sh
# installs build and run, the Docker image's build stage build and package, scripts/test.sh
# and .ci/run everything.
set -euo pipefail

build=(
  build-essential cmake ninja-build pkg-config
  # messages and DDS: Fast DDS, and Cyclone DDS as the second implementation
  libfastrtps-dev libfastcdr-dev fastddsgen cyclonedds-dev
  # runtime
  libyaml-cpp-dev libfmt-dev
  # calibration: configuration and data files (JSON)
  nlohmann-json3-dev
  # bags: rosbag2's sqlite3 storage, MCAP's zstd, lz4 and CRC-32; the overlay's PNG snapshots
  libsqlite3-dev libzstd-dev liblz4-dev zlib1g-dev
  # vision: images, geometry, least squares (camera calibration)
  libopencv-dev libeigen3-dev libceres-dev
  # the Foxglove WebSocket bridge (TLS by OpenSSL)
  libwebsocketpp-dev libasio-dev libssl-dev
)
run=(
  # Fast DDS's discovery server and shared-memory cleanup (fastdds), the sqlite3 shell to look
  # inside bags, openssl for the viewer's TLS certificates and the security credentials
  fastdds-tools sqlite3 openssl
)
package=(
  # cpack's Debian packages: dpkg-shlibdeps and file
  dpkg-dev file
)
test=(
  # GoogleTest, network namespaces for the multi-host tests, the formatting check, the
  # browser test (Node and npm come with the machine)
  libgtest-dev libgmock-dev iproute2 clang-format chromium
  # the compiler cache the builds use when it is there (CMakeLists.txt)
  ccache
  # sanitizer builds and fuzzing (scripts/sanitize.sh, scripts/fuzz.sh): clang with its
  # sanitizer runtimes and libFuzzer
  clang libclang-rt-14-dev libfuzzer-14-dev
  # the Debian package's test in a clean Debian 12 root
  debootstrap
  # benchmarks: instruction counts
  valgrind
  # a camera host's clock shifted for the clock check's tests; chrony to check the
  # synchronisation configurations the README gives
  faketime chrony
  # containers: the engine and compose, for scripts/docker_test.sh
  docker.io docker-compose
)

groups=("$@")
[ ${#groups[@]} -gt 0 ] || groups=(all)
packages=()
for group in "${groups[@]}"; do
  case "$group" in
    build) packages+=("${build[@]}") ;;
    run) packages+=("${run[@]}") ;;
    package) packages+=("${package[@]}") ;;
    test) packages+=("${test[@]}") ;;
    all) packages+=("${build[@]}" "${run[@]}" "${package[@]}" "${test[@]}") ;;
    *)
      echo "install_deps: unknown group '$group' (build, run, package, test, all)" >&2
      exit 2
      ;;
  esac
done

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  sudo="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
echo "install_deps: installing ${missing[*]}"
# An index that is missing or a day old is read again first; a failed install once more.
if [ -z "$(find /var/lib/apt/lists -maxdepth 1 -name '*Packages*' -mtime -1 2>/dev/null | head -1)" ]; then
  $sudo apt-get update -q
fi
if ! $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"; then
  $sudo apt-get update -q
  $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
