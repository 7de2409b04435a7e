# Which tests run where, so that each test runs once (sourced by scripts/test.sh and
# scripts/sanitize.sh). The AddressSanitizer+UBSan build runs every test but these; the plain
# g++ build runs these alone:
#
# - Install.*: check what the plain build installs and packages (the example against an
#   installed prefix, the Debian package in a clean Debian root); a sanitized build is never
#   installed or packaged.
# - Tests that assume real-time speed, which AddressSanitizer takes several times from: the
#   follower demo's pointing bounds, the browser's frame drawn with its fiducials, the
#   independent client's poses with their truth and the ROS 2 outputs decoded (the pipeline
#   keeping up with the camera's 30 Hz; under AddressSanitizer beside other tests the followed
#   board was lost and no output came in 60 s, twice), the calibration recorder's Ctrl-C in the
#   third LED cycle (under load a camera missed a whole cycle in 1 of 8 runs), and the tracking
#   volume's demo (four cameras rendering and detecting 1280x720 frames at 30 Hz).
#   They run one at a time (realtime_tests): beside the busy-core loads below the follower
#   demo's turret fell to 7 Hz.
# - The tracking volume's figures on long rendered sessions (eight cameras; the cameras
#   calibrated from a minute of rendered waving): 2 minutes under AddressSanitizer for
#   arithmetic the shorter VolumeAccuracy tests run through the same code under it.
# - The two slow-subscriber loads per DDS implementation: paced by the slow subscriber, about
#   a minute each under the sanitizer; their publisher blocks and wakes as under the stalling
#   subscriber, which the sanitizer build runs.
realtime_tests='FollowerDemo\.TurretCentresBase.*|FoxgloveBridgeTest\.(TheViewerDraws|AnIndependentClient|RosOwnDefinitions).*'
realtime_tests+='|FoxgloveBridgeVolume\..*'
realtime_tests+='|CalibrationRecordTool\.CtrlCStopsTheLiveRecording.*|VolumeDemo\..*'
plain_only_tests="Install\\..*|$realtime_tests"
plain_only_tests+='|VolumeAccuracy\.(EightCameras|CamerasCalibrated).*'
plain_only_tests+='|(cyclonedds\.)?Dds/ReliableUnderLoad\.LosesNothingAcrossTenThousandMessages/(BusyCoresAnd)?SlowSubscriber( .*)?'
# Of those, the loads that keep every core busy, which scripts/test.sh runs after the others.
busy_core_tests='(cyclonedds\.)?Dds/ReliableUnderLoad\.LosesNothingAcrossTenThousandMessages/BusyCoresAndSlowSubscriber( .*)?'
# The executables these tests are in: test/CMakeLists.txt's mocap_plain_tests target, which the
# plain build compiles (a test named above from another executable must be added there).
