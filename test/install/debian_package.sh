#!/usr/bin/env bash
# Builds the Debian packages (cpack -G DEB: mocap-graph, -camera, -dev), checks what each holds,
# installs mocap-graph with apt into a clean Debian 12 root (debootstrap, minbase) and runs the
# shipped tracking demo from the installed share directory: exit 0, poses published, every frame
# tracked; then installs mocap-graph-camera beside it and runs its tool. Needs root, debootstrap
# and Debian's archive.
#
#   debian_package.sh BUILD_DIR
set -euo pipefail
build_dir=$(realpath "$1")
scripts=$(realpath "$(dirname "$0")/../../scripts")
root=$(mktemp -d /var/tmp/mocap_deb_root.XXXXXX)
# Never through a mount: the root has the host's /dev bound into it (scripts/remove_tree.sh).
cleanup() { "$scripts/remove_tree.sh" "$root"; }
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cd "$build_dir"
rm -f mocap-graph*_amd64.deb
cpack -G DEB > cpack.log 2>&1 || { cat cpack.log; fail "cpack -G DEB"; }
deb=$(ls mocap-graph_*_amd64.deb)
camera=$(ls mocap-graph-camera_*_amd64.deb)
dev=$(ls mocap-graph-dev_*_amd64.deb)
depends=$(dpkg-deb -f "$deb" Depends)
grep -q "libfastrtps2.9" <<< "$depends" || fail "$deb: Depends lacks Fast DDS: $depends"
# The lean part: no OpenCV video or image-file stack (FFmpeg, GStreamer, GDAL), no headers.
! grep -qE "videoio|imgcodecs" <<< "$depends" || fail "$deb: Depends has OpenCV's I/O: $depends"
# (Listings in files: grep -q on a pipe would end dpkg-deb early, a failure under pipefail.)
for d in "$deb" "$camera" "$dev"; do dpkg-deb -c "$d" | awk '{ print $6 }' > "$d.contents"; done
! grep -qE "^\./usr/include/|\.a$|camera_source|mocap_calibrate$" "$deb.contents" ||
  fail "$deb holds what -dev or -camera should: $(grep -E "include/|\.a$|camera_source|calibrate$" "$deb.contents" | head -3)"
grep -q "libmocap_plugin_camera_source.so" "$camera.contents" || fail "$camera lacks camera_source"
dpkg-deb -f "$camera" Depends | grep -q "mocap-graph (= " || fail "$camera does not depend on $deb"
grep -q "usr/lib/cmake/mocap_graph/mocap_graphConfig.cmake" "$dev.contents" ||
  fail "$dev lacks find_package(mocap_graph)"
grep -q "usr/include/mocap/component.hpp" "$dev.contents" || fail "$dev lacks the component API"

"$scripts/make_debian_root.sh" "$root" || fail "no Debian 12 root"
cp "$deb" "$camera" "$root/tmp/"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount -t proc proc "$root/proc"
mount --bind /dev "$root/dev"
chroot "$root" sh -c "apt-get update -q && DEBIAN_FRONTEND=noninteractive \
  apt-get install -y -q --no-install-recommends /tmp/$deb" > apt.log 2>&1 ||
  { tail -30 apt.log; fail "apt install ./$deb in a clean Debian 12 root"; }

domain=$((100 + $$ % 100))
chroot "$root" sh -c "cd /usr/share/mocap_graph && MOCAP_DOMAIN_ID=$domain \
  timeout 120 mocap_launch launch_yaml/mobile_mocap_demo.yaml --duration 5 \
  --set viewer.port=0" > demo.log 2>&1 ||
  { cat demo.log; fail "mocap_launch from the installed package exited with $?"; }
poses=$(sed -n 's/.*\[boards\]: [0-9]* arrays: \([0-9]*\) poses.*/\1/p' demo.log)
[ "${poses:-0}" -ge 100 ] || { cat demo.log; fail "only ${poses:-0} poses in 5 s"; }
grep -q "| 0 | 100.00 % |" demo.log || { cat demo.log; fail "not every frame tracked"; }
chroot "$root" sh -c "DEBIAN_FRONTEND=noninteractive \
  apt-get install -y -q --no-install-recommends /tmp/$camera" > apt.log 2>&1 ||
  { tail -30 apt.log; fail "apt install ./$camera beside $deb"; }
chroot "$root" sh -c "mocap_calibrate --help && mocap_launch --plugins" > camera.log 2>&1 ||
  { cat camera.log; fail "mocap_calibrate from $camera"; }
grep -q "^camera_source " camera.log || { cat camera.log; fail "camera_source not listed once $camera is installed"; }
echo "PASS: $deb ($(du -h "$deb" | cut -f1)) installed by apt in a clean Debian 12 root; the demo published $poses poses; $camera beside it adds camera_source and mocap_calibrate"
