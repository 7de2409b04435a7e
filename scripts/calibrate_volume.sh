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
#                                      [--viewer-port PORT] [--hold SECONDS]
#
# While the board is waved, each camera's coverage (its image's regions the board has filled,
# the shots it shares with another camera: the volume_calibration_coverage component) shows as a
# bar a camera with what is still missing, redrawn on a terminal, and in the page at
# http://localhost:PORT/ (default 8765; 0: any free port, named in waved.log). The solve
# (launch_yaml/volume_calibration_solve.yaml, the session mocap_volume_calibrate runs) shows its
# progress as a bar and in the page, then prints its report, which the page shows too: each
# camera's RMS, where it is and how far from its input file's pose, a picture of the volume.
# The page keeps the report until Enter on a terminal, for --hold SECONDS otherwise (default 0;
# SIGINT or SIGTERM ends the hold).
# solve.log holds the solve's log.
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
wave_s=120 floor_s=3 marks="0,0 1,0 0,1 -1,0 0,-1 1,1 -1,1 -1,-1 1,-1" viewer_port=8765 hold=
while [ $# -gt 0 ]; do
  case "$1" in
    --wave) wave_s="${2:?}"; shift 2 ;;
    --floor) floor_s="${2:?}"; shift 2 ;;
    --marks) marks="${2:?}"; shift 2 ;;
    --viewer-port) viewer_port="${2:?}"; shift 2 ;;
    --hold) hold="${2:?}"; shift 2 ;;
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
# On a terminal, LINES (a command printing them) redrawn in place every PERIOD seconds while
# process PID runs.
redraw_while() {
  local pid=$1 period=$2 shown=0 lines
  shift 2
  while kill -0 "$pid" 2> /dev/null; do
    lines=$("$@")
    if [ -n "$lines" ]; then
      [ "$shown" = 0 ] || printf '\033[%dA' "$shown"
      while IFS= read -r line; do printf '\033[K  %s\n' "$line"; done <<< "$lines"
      shown=$(wc -l <<< "$lines")
    fi
    sleep "$period"
  done
}
[ ! -t 1 ] || redraw_while "$wave" 1 coverage
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
    floors+=("\"$out/$name:$x,$y\"")
  done
done

# The solve, in the page on the same port. It ends once its report is out, or, to keep the
# report in the page, when this script stops it.
keep_page=false
[ -z "$hold" ] && [ ! -t 1 ] && hold=0
[ "$hold" = 0 ] || keep_page=true
# SIGINT or SIGTERM from here on stops the solve, or ends the hold (and the page with it).
stopped=false pause=
trap 'stopped=true; [ -z "$pause" ] || kill "$pause" 2> /dev/null' INT TERM
echo "calibrate_volume: solving (progress: http://localhost:$viewer_port/)"
floor_list=$(IFS=,; echo "${floors[*]}")
"$bin_dir/mocap_launch" "$root/launch_yaml/volume_calibration_solve.yaml" \
  --set "solver.waved=\"$out/waved\"" --set "solver.floor=[$floor_list]" \
  --set "solver.output=\"$out/cameras\"" --set "solver.exit_when_done=$([ "$keep_page" = true ] &&
    echo false || echo true)" --set "viewer.port=$viewer_port" > "$out/solve.log" 2>&1 &
solve=$!
# The solve's latest progress line ("solve [=====     ]  45 % solving, iteration 7, ...").
progress() { { grep -o "solve \[.*" "$out/solve.log" || true; } | tail -n 1; }
finished() { grep -qE "solve \[.*\] +[0-9]+ % (done|failed)" "$out/solve.log"; }
until finished || ! kill -0 "$solve" 2> /dev/null || [ "$stopped" = true ]; do
  [ ! -t 1 ] || printf '\r\033[K  %s' "$(progress)"
  sleep 0.2
done
if [ -t 1 ]; then printf '\r\033[K  %s\n' "$(progress)"; else echo "calibrate_volume: $(progress)"; fi
if ! grep -qE "solve \[.*\] +[0-9]+ % done" "$out/solve.log"; then
  kill -INT "$solve" 2> /dev/null || true
  wait "$solve" || true
  tail -n 20 "$out/solve.log"
  exit 1
fi
grep -o "report: .*" "$out/solve.log" | sed 's/^report: //'
if [ "$keep_page" = true ]; then
  if [ "$stopped" = true ]; then
    :
  elif [ -z "$hold" ]; then
    read -r -p "calibrate_volume: the report is in the page at http://localhost:$viewer_port/; Enter closes it " _ || true
  else
    sleep "$hold" &
    pause=$!
    wait "$pause" || true
  fi
  kill -INT "$solve" 2> /dev/null || true
fi
wait "$solve"
