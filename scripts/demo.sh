#!/usr/bin/env bash
# Sets everything up and runs the tracking demo (launch_yaml/mobile_mocap_demo.yaml) for 10 s.
# Extra arguments go to mocap_launch: --duration 0 runs until Ctrl-C.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
exec build/bin/mocap_launch launch_yaml/mobile_mocap_demo.yaml --duration 10 "$@"
