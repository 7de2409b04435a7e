#!/usr/bin/env bash
# Sets everything up and runs the follower demo (launch_yaml/follower_demo.yaml) for 40 s: the
# tracking pipeline on a camera carried by a pan/tilt turret on a mobile base, following a
# person with a board. Extra arguments go to mocap_launch: --duration 0 runs until Ctrl-C.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
exec build/bin/mocap_launch launch_yaml/follower_demo.yaml --duration 40 "$@"
