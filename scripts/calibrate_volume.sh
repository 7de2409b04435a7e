#!/usr/bin/env bash
# The volume demo's cameras calibrated from data, in one command: records the board carried
# through the volume (launch_yaml/volume_calibration.yaml, config/volume/calibration_wave.yaml)
# and then lying on the floor at each mark (config/volume/calibration_floor.yaml, moved there),
# each into a bag, and solves them with mocap_volume_calibrate, which writes the four camera
# files with their calibrated poses into OUTPUT/cameras. In OUTPUT it writes (and replaces)
# waved/ and floor_X_Y[_turned]/ (the bags), their .log and .yaml files and cameras/, nothing
# else.
#
#   scripts/calibrate_volume.sh OUTPUT [--wave SECONDS] [--floor SECONDS] [--marks "X,Y ..."]
#                                      [--viewer-port PORT]
#
# While the board is waved, each camera's coverage (its image's regions the board has filled,
# the shots it shares with another camera: the volume_calibration_coverage component) shows as a
# bar a camera with what is still missing, redrawn on a terminal, and in the page at
# http://localhost:PORT/ (default 8765; 0: any free port, named in waved.log).
#
# Defaults: 120 s of waving (the wave's path once round); 3 s on the floor at each of the marks
# "0,0 1,0 0,1 -1,0 0,-1 1,1 -1,1 -1,-1 1,-1" (metres: the centre, 1 m along each axis and the
# corners of that square; "0,0" alone: the one board's axes are the room's), laid twice at each,
# the second time turned half round about its centre: the two centres' mean cancels much of what
# the still board adds (its markers' detection biases, a pattern whose centre is off its origin).
# volume_calibration_bench compares waves and floors. The demo on the calibrated cameras:
#   build/bin/mocap_launch launch_yaml/volume_demo.yaml --set \
#     "fusion.cameras=[OUTPUT/cameras/cam_0.yaml, ..., OUTPUT/cameras/cam_3.yaml]"
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin_dir="${MOCAP_BIN_DIR:-$root/build/bin}"
usage() {
  sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'
  exit 2
}
[ $# -ge 1 ] || usage
out="$1"
shift
wave_s=120 floor_s=3 marks="0,0 1,0 0,1 -1,0 0,-1 1,1 -1,1 -1,-1 1,-1" viewer_port=8765
while [ $# -gt 0 ]; do
  case "$1" in
    --wave) wave_s="${2:?}"; shift 2 ;;
    --floor) floor_s="${2:?}"; shift 2 ;;
    --marks) marks="${2:?}"; shift 2 ;;
    --viewer-port) viewer_port="${2:?}"; shift 2 ;;
    *) echo "calibrate_volume.sh: unknown option $1" >&2; usage ;;
  esac
done
launch="$root/launch_yaml/volume_calibration.yaml"
mkdir -p "$out"
# Each bag goes into a folder of its own name, written afresh; nothing else in OUTPUT is touched.
rm -rf "$out/waved"
echo "calibrate_volume: recording ${wave_s} s of the board carried through the volume" \
  "(coverage: http://localhost:$viewer_port/)"
"$bin_dir/mocap_launch" "$launch" --duration "$wave_s" --set "recorder.output=$out/waved" \
  --set "viewer.port=$viewer_port" > "$out/waved.log" 2>&1 &
wave=$!
# The coverage component's latest line for each camera ("coverage cam_0 [====   ] 40 %: ...").
coverage() { { grep -o "coverage cam_[0-9]* \[.*" "$out/waved.log" || true; } | tail -n 4; }
if [ -t 1 ]; then
  shown=0
  while kill -0 "$wave" 2> /dev/null; do
    lines=$(coverage)
    if [ -n "$lines" ]; then
      [ "$shown" = 0 ] || printf '\033[%dA' "$shown"
      while IFS= read -r line; do printf '\033[K  %s\n' "$line"; done <<< "$lines"
      shown=$(wc -l <<< "$lines")
    fi
    sleep 1
  done
fi
wait "$wave" || { tail -n 20 "$out/waved.log"; exit 1; }
[ -t 1 ] || coverage | sed 's/^/calibrate_volume: /'
floor_scene="$root/config/volume/calibration_floor.yaml"
floors=()
turns="0 180"
[ "$(wc -w <<< "$marks")" -ge 3 ] || turns=0  # laid once, the board's axes are the room's
for mark in $marks; do
  x="${mark%,*}" y="${mark#*,}"
  for turn in $turns; do
    name="floor_${x}_${y}"
    [ "$turn" = 0 ] || name+="_turned"
    # The shipped floor scene, the board's centre moved onto the mark and turned about its
    # normal (the scene's roll).
    sed -e "s/position: \[0, 0, 0\]/position: [$x, $y, 0]/" \
      -e "s/rpy_deg: \[0, 180, 0\]/rpy_deg: [$turn, 180, 0]/" "$floor_scene" > "$out/$name.yaml"
    grep -q "position: \[$x, $y, 0\], rpy_deg: \[$turn, 180, 0\]" "$out/$name.yaml" || {
      echo "calibrate_volume: $floor_scene has no board at [0, 0, 0], rpy_deg [0, 180, 0]" >&2
      exit 1
    }
    echo "calibrate_volume: recording ${floor_s} s of the board on the floor at ($x, $y)," \
      "turned ${turn} deg"
    on_floor=()
    for c in 0 1 2 3; do on_floor+=(--set "cam_$c.scene=$out/$name.yaml"); done
    rm -rf "${out:?}/$name"
    "$bin_dir/mocap_launch" "$launch" --duration "$floor_s" --set "recorder.output=$out/$name" \
      --set viewer.port=0 "${on_floor[@]}" > "$out/$name.log" 2>&1 ||
      { tail -n 20 "$out/$name.log"; exit 1; }
    floors+=(--floor "$out/$name:$x,$y")
  done
done
exec "$bin_dir/mocap_volume_calibrate" --waved "$out/waved" "${floors[@]}" \
  --output "$out/cameras" "$root"/config/volume/cameras/cam_{0,1,2,3}.yaml
