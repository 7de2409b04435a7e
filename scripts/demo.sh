#!/usr/bin/env bash
# Sets everything up and runs the demo graph (launch_yaml/demo.yaml) until Ctrl-C.
# Extra arguments go to mocap_launch, e.g. --duration 10.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
scripts/build.sh
exec build/bin/mocap_launch launch_yaml/demo.yaml "$@"
