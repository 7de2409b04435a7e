#!/usr/bin/env bash
# Installs the Debian 12 packages mocap-graph needs: the one list. Safe to run again: when
# everything is installed it changes nothing, and it reads the package index only when a
# package is missing.
set -euo pipefail

packages=(
  # build
  build-essential cmake ninja-build pkg-config
  # messages and DDS: Fast DDS, and Cyclone DDS as the second implementation
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools cyclonedds-dev
  # runtime
  libyaml-cpp-dev libfmt-dev
  # calibration: configuration and data files (JSON)
  nlohmann-json3-dev
  # bags: rosbag2's sqlite3 storage (the sqlite3 shell to look inside), MCAP's zstd, lz4 and CRC-32
  libsqlite3-dev sqlite3 libzstd-dev liblz4-dev zlib1g-dev
  # vision: images, geometry, least squares (camera calibration)
  libopencv-dev libeigen3-dev libceres-dev
  # the overlay's PNG snapshots
  zlib1g-dev
  # the Foxglove WebSocket bridge (TLS by OpenSSL); its browser test (Node and npm come with the
  # machine) and its test certificates
  libwebsocketpp-dev libasio-dev libssl-dev openssl chromium
  # tests: GoogleTest, network namespaces for the multi-host tests, formatting check
  libgtest-dev libgmock-dev iproute2 clang-format
  # sanitizer builds and fuzzing (scripts/sanitize.sh, scripts/fuzz.sh): clang with its
  # sanitizer runtimes and libFuzzer
  clang libclang-rt-14-dev libfuzzer-14-dev
  # the Debian package (cpack: dpkg-shlibdeps, file) and its test in a clean Debian 12 root
  dpkg-dev file debootstrap
  # benchmarks: instruction counts
  valgrind
  # containers: the engine and compose, for scripts/docker_test.sh
  docker.io docker-compose
)

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
