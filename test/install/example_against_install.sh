#!/usr/bin/env bash
# Installs mocap-graph to a temporary prefix, builds examples/pose_filter against that prefix
# alone (a copy outside the source tree, a fresh configure), runs its launch file with the
# shipped tracking pipeline, and checks /mocap/filtered_poses through the installed
# mocap_topic and mocap_bag: the example's own message type, filtered values near the raw ones.
# Then builds and runs the README's "Writing your own component" files the same way.
#
#   example_against_install.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=$(realpath "$1")
build_dir=$(realpath "$2")
work=$(mktemp -d /tmp/mocap_install_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

prefix=$work/prefix
cmake --install "$build_dir" --prefix "$prefix" > "$work/install.log"
for file in bin/mocap_launch bin/mocap_topic bin/mocap_bag lib/libmocap_runtime.so \
            lib/mocap_graph/plugins/libmocap_plugin_constellation_tracker.so \
            lib/mocap_graph/plugins/libmocap_plugin_pose_estimator.so \
            include/mocap/component.hpp include/geometry_msgs/msg/pose.hpp \
            include/mocap/calibration/camera_model.hpp include/mocap/bag/bag_reader.hpp \
            share/mocap_graph/config/constellations.yaml \
            share/mocap_graph/launch_yaml/mobile_mocap_demo.yaml \
            share/mocap_graph/idl/geometry_msgs/msg/Pose.idl \
            lib/cmake/mocap_graph/mocap_graphConfig.cmake; do
  [ -e "$prefix/$file" ] || fail "cmake --install did not install $file"
done

cp -r "$source_dir/examples/pose_filter" "$work/pose_filter"
cd "$work/pose_filter"
cmake -S . -B build -G Ninja -DCMAKE_PREFIX_PATH="$prefix" > "$work/configure.log" 2>&1 ||
  { cat "$work/configure.log"; fail "the example does not configure against the prefix"; }
cmake --build build > "$work/build.log" 2>&1 ||
  { cat "$work/build.log"; fail "the example does not build against the prefix"; }
if grep -rIl --exclude-dir=.fastddsgen "$source_dir" build > "$work/leaks.txt"; then
  fail "the example's build refers to the source tree $source_dir: $(head -3 "$work/leaks.txt" | tr '\n' ' ')"
fi
[ -f build/plugins/libmocap_plugin_pose_filter.so ] || fail "no pose_filter plugin"
[ -f build/plugins/libmocap_messages_pose_filter_msgs.so ] || fail "no message library"

export MOCAP_PLUGIN_PATH=$work/pose_filter/build/plugins
export MOCAP_DOMAIN_ID=$((100 + $$ % 100))
"$prefix/bin/mocap_launch" launch/pose_filter_demo.yaml --check > "$work/check.log" 2>&1 ||
  { cat "$work/check.log"; fail "mocap_launch --check refuses the example's launch file"; }
"$prefix/bin/mocap_launch" launch/pose_filter_demo.yaml --duration 8 > "$work/launch.log" 2>&1 &
launch=$!
timeout 30 "$prefix/bin/mocap_topic" echo /mocap/filtered_poses --count 5 --full \
  > "$work/echo.txt" 2> "$work/echo.err" || true
timeout 30 "$prefix/bin/mocap_bag" record -o "$work/bag" --duration 2 /mocap/filtered_poses \
  > "$work/record.log" 2>&1 || true
wait "$launch" || { cat "$work/launch.log"; fail "mocap_launch exited with $?"; }
grep -q "arrays filtered" "$work/launch.log" || { cat "$work/launch.log"; fail "pose_filter did not run"; }

# Each filtered pose within 5 cm of its raw pose, smoothing as the launch file set it, and the
# two boards of the scene present.
awk -v file="$work/echo.txt" '
  /^    (pose|raw):/ { part = $1 }
  /^      (position|orientation):/ { sub_part = $1 }
  /^        [xyz]: / && sub_part == "position:" { value[part $1] = $2 }
  /^      orientation:/ { if (part == "raw:") { d = 0
      for (c in axes) { diff = value["pose:" axes[c] ":"] - value["raw:" axes[c] ":"]; d += diff * diff }
      if (sqrt(d) > 0.05) { print "filtered pose " sqrt(d) " m from the raw one"; bad = 1 }
      poses++ } }
  /^    smoothing: / { if ($0 !~ /\[0\.3, 0\.3\]/) { print "smoothing " $0; bad = 1 } }
  /^  - name: "board_[ab]"/ { names[$3] = 1 }
  BEGIN { axes[1] = "x"; axes[2] = "y"; axes[3] = "z" }
  END { if (poses < 10) { print "only " poses " poses in " file; bad = 1 }
        if (length(names) != 2) { print "expected board_a and board_b"; bad = 1 }
        exit bad }' "$work/echo.txt" || { head -40 "$work/echo.txt"; cat "$work/echo.err"; fail "filtered poses"; }

"$prefix/bin/mocap_bag" info "$work/bag" > "$work/info.txt" 2>&1 || { cat "$work/record.log"; fail "no bag"; }
grep -q "pose_filter_msgs/msg/FilteredPoseArray" "$work/info.txt" ||
  { cat "$work/info.txt"; fail "the bag does not hold pose_filter_msgs/msg/FilteredPoseArray"; }
# The README's five-minute path ("Writing your own component"), its three files as they stand.
mkdir "$work/counter"
cd "$work/counter"
awk '/^## Writing your own component/ { on = 1 } /^## How messages travel/ { on = 0 }
     on && /^   ```(cpp|cmake|yaml)$/ { lang = substr($1, 4); n++; next }
     on && /^   ```$/ { lang = ""; next }
     lang != "" && n <= 3 { file = (lang == "cpp") ? "counter.cpp" : (lang == "cmake") ? \
       "CMakeLists.txt" : "counter.yaml"; sub(/^   /, ""); print > file }' "$source_dir/README.md"
for file in counter.cpp CMakeLists.txt counter.yaml; do
  [ -s "$file" ] || fail "README.md: no $file in \"Writing your own component\""
done
{ cmake -S . -B build -G Ninja -DCMAKE_PREFIX_PATH="$prefix" && cmake --build build; } \
  > "$work/counter.log" 2>&1 || { cat "$work/counter.log"; fail "the README's counter does not build"; }
MOCAP_PLUGIN_PATH=$work/counter/build/plugins "$prefix/bin/mocap_launch" counter.yaml \
  --duration 3 > "$work/counter_run.log" 2>&1 || { cat "$work/counter_run.log"; fail "counter.yaml"; }
grep -q "\[counter\]: 60 poses" "$work/counter_run.log" ||
  { cat "$work/counter_run.log"; fail "the README's counter did not count 60 poses"; }

echo "PASS: installed, built the example against the prefix, $(grep -c '^  - name' "$work/echo.txt") filtered poses checked, bag: $(grep FilteredPoseArray "$work/info.txt" | tr -s ' ')"
