#!/usr/bin/env bash
# Builds the tests under sanitizers with clang and runs them; any report fails the run.
#
#   scripts/sanitize.sh address [CTEST ARGS]  AddressSanitizer, LeakSanitizer and
#       UndefinedBehaviorSanitizer in build-asan/: the tests of the part `address` (all but the
#       few only the plain build runs: test/CMakeLists.txt), and the fuzzers (scripts/fuzz.sh
#       runs them from this build).
#   scripts/sanitize.sh thread [CTEST ARGS]   ThreadSanitizer in build-tsan/: the threaded
#       parts (below) and their tests, and only those.
#   scripts/sanitize.sh MODE --build-only     builds, runs nothing.
#
# Both build at -O1 with line tables only: stack traces name file and line, and the build
# takes about half the time of -O2 with full debug information.
# Reports that are not ours are suppressed in test/sanitizers/*.supp, one line each with why.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-}
shift || true
build_only=false
if [ "${1:-}" = --build-only ]; then
  build_only=true
  shift
fi
case "$mode" in
  address) build=build-asan ;;
  thread)
    build=build-tsan
    # The runtime's unit tests (executor, timers, component host and its workers, intra-process
    # and shared memory transports; not ShutdownSignal's: they fork a child that starts a
    # thread, which ThreadSanitizer does not support after a fork, and there the child twice
    # missed its stop requests; ASan runs them, and the graph tests below signal whole
    # processes), the graph and DDS
    # tests on both implementations (each process a multi-threaded executor), Discovery Servers and
    # mixed Fast DDS / Cyclone DDS graphs (not the DDS security tests: Fast DDS 2.9.1 races with
    # itself in the secure handshake, two receive threads writing one ReaderProxyData under
    # different locks, seen with Cyclone DDS starting it), the bag tools' record, play and stop
    # tests and the bag recorder and player components in a running pipeline, the recorder's
    # forced-exit hook, which runs beside its writer thread, the VRPN tracker server's thread beside
    # the reports of the pose outputs; the viewer's WebSocket server thread and its client queues,
    # pixart_bridge's serial reader and the simulated PixArt box, the Dynamixel follower's worker
    # and the simulated AX-12 chain, and camera_source's capture thread.
    tsan_tests='^(CdrFormat|IdlSchema|ComponentHost|Lifecycle|TopicFamilies|Executor|DispatchTest|Timers|SharedMemoryCleanup|IntraProcess|([a-z]+\.)?(Graph|Dds|MocapBag|Playback|Patterns/MocapBagStops|Storages/MocapBagCutShort|DiscoveryServer)|MixedDds(\.|/MixedTracking\.)|Launcher|BagPipeline|BagRecorderComponent|VrpnServer|PoseOutputs|Px4Odometry|ClientQueue|FoxgloveBridge(Test|Network|Security|Pixart)|PixartBridge|PixartBoxSimPlugin|SimulatedSlcanAdaptor|SerialPort|PseudoTerminal|SimulatedAx12(Chain|Faults)|Ax12SimPlugin|DynamixelBus|DynamixelFollowerPlugin|TurretFollower|CameraSourcePlugin|ImageDirectorySource|VideoFileSource)'
    ;;
  *)
    echo "usage: scripts/sanitize.sh address|thread [ctest arguments]" >&2
    exit 2
    ;;
esac
source scripts/sanitizer_env.sh
scripts/install_deps.sh

cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Sanitize \
  -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -gline-tables-only" -DMOCAP_SANITIZE="$mode" \
  -DMOCAP_WERROR=ON -DMOCAP_BUILD_TESTS=ON -DMOCAP_BUILD_BENCHMARKS=OFF > /dev/null
if [ "$mode" = address ]; then
  cmake --build "$build" --parallel "$(nproc)"
  # Every test but those only the plain build runs (test/CMakeLists.txt: the parts of CI).
  filter=(-L '^address$')
else
  # The threaded parts and their tests (above), and only those.
  cmake --build "$build" --parallel "$(nproc)" --target mocap_unit_tests \
    mocap_integration_tests mocap_test_bag_tools mocap_test_bag_pipeline \
    mocap_plugin_bag_recorder mocap_plugin_bag_player mocap_test_pose_outputs \
    mocap_test_px4_odometry mocap_test_vrpn_server mocap_test_client_queue \
    mocap_test_foxglove_bridge mocap_test_pixart_bridge mocap_test_pixart_box_sim \
    mocap_test_can_io mocap_test_ax12_sim mocap_test_dynamixel_bus mocap_test_turret_follower \
    mocap_test_camera_source
  # Not the tests only the plain build runs (test/CMakeLists.txt: real-time speed, slow
  # subscribers, packaging).
  filter=(-R "$tsan_tests" -L '^address$')
fi
$build_only && exit 0
cmake -DBUILD="$build" -P scripts/check_test_parts.cmake
# The tests' independent clients and readers (pinned in test/package-lock.json).
npm ci --prefix test --no-audit --no-fund --loglevel=error
# Two tests per core: they wait on processes, discovery and the network much of the time (one
# per core kept the two cores of a CI machine 57 % busy, two per core 80 %, and took 243 s
# instead of 343 s).
parallel=${MOCAP_TEST_PARALLEL:-$((2 * $(nproc)))}
if [ "$mode" = address ]; then
  MOCAP_TEST_PARALLEL=$parallel scripts/run_tests.sh "$build" "$mode sanitizer" "${filter[@]}" "$@"
  exit
fi
# Under ThreadSanitizer, which slows the DDS stop paths far more, the loads that keep every core
# busy run after the others, one per core: beside other tests a stopping publisher once dropped
# its last sample (cyclonedds ARestartedSubscriberProcessReceivesAgain/BusyCoresAndSlowSubscriber).
busy_cores='([a-z]+\.)?Dds/ReliableUnderLoad\..*/BusyCores.*'
MOCAP_TEST_PARALLEL=$parallel scripts/run_tests.sh "$build" "$mode sanitizer" "${filter[@]}" \
  -E "^($busy_cores)\$" "$@"
# (All of them DDS tests, which the threaded parts include.)
MOCAP_TEST_PARALLEL=${MOCAP_TEST_PARALLEL:-$(nproc)} scripts/run_tests.sh "$build" \
  "$mode sanitizer, busy cores" -R "^($busy_cores)\$" -L '^address$' "$@"
