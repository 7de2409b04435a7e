#!/usr/bin/env bash
# The volume demo's cameras calibrated from data, in one command: records the board carried
# through the volume (launch_yaml/volume_calibration.yaml, config/volume/calibration_wave.yaml)
# and then lying on the floor (config/volume/calibration_floor.yaml), each into a bag, and
# solves them with mocap_volume_calibrate, which writes the four camera files with their
# calibrated poses into OUTPUT/cameras.
#
#   scripts/calibrate_volume.sh OUTPUT [--wave SECONDS] [--floor SECONDS]
#
# Defaults: 30 s of waving, 10 s on the floor. The demo on the calibrated cameras:
#   build/bin/mocap_launch launch_yaml/volume_demo.yaml --set \
#     "fusion.cameras=[OUTPUT/cameras/cam_0.yaml, ..., OUTPUT/cameras/cam_3.yaml]"
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin_dir="${MOCAP_BIN_DIR:-$root/build/bin}"
usage() {
  sed -n '2,13p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 2
}
[ $# -ge 1 ] || usage
out="$1"
shift
wave_s=30 floor_s=10
while [ $# -gt 0 ]; do
  case "$1" in
    --wave) wave_s="${2:?}"; shift 2 ;;
    --floor) floor_s="${2:?}"; shift 2 ;;
    *) echo "calibrate_volume.sh: unknown option $1" >&2; usage ;;
  esac
done
launch="$root/launch_yaml/volume_calibration.yaml"
mkdir -p "$out"
rm -rf "$out/waved" "$out/floor"
echo "calibrate_volume: recording ${wave_s} s of the board carried through the volume"
"$bin_dir/mocap_launch" "$launch" --duration "$wave_s" --set "recorder.output=$out/waved" \
  > "$out/waved.log" 2>&1 || { tail -n 20 "$out/waved.log"; exit 1; }
echo "calibrate_volume: recording ${floor_s} s of the board on the floor"
on_floor=()
for c in 0 1 2 3; do
  on_floor+=(--set "cam_$c.scene=$root/config/volume/calibration_floor.yaml")
done
"$bin_dir/mocap_launch" "$launch" --duration "$floor_s" --set "recorder.output=$out/floor" \
  "${on_floor[@]}" > "$out/floor.log" 2>&1 || { tail -n 20 "$out/floor.log"; exit 1; }
exec "$bin_dir/mocap_volume_calibrate" --waved "$out/waved" --floor "$out/floor" \
  --output "$out/cameras" "$root"/config/volume/cameras/cam_{0,1,2,3}.yaml
