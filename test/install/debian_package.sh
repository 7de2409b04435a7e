#!/usr/bin/env bash
# Builds the Debian package (cpack -G DEB), installs it with apt into a clean Debian 12 root
# (debootstrap, minbase) and runs the shipped tracking demo from the installed share directory:
# exit 0, poses published, every frame tracked. Needs root, debootstrap and Debian's archive.
#
#   debian_package.sh BUILD_DIR
set -euo pipefail
build_dir=$(realpath "$1")
scripts=$(realpath "$(dirname "$0")/../../scripts")
root=$(mktemp -d /var/tmp/mocap_deb_root.XXXXXX)
cleanup() {
  umount "$root/proc" "$root/dev" 2>/dev/null || true
  rm -rf "$root"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cd "$build_dir"
rm -f mocap-graph_*_amd64.deb
cpack -G DEB > cpack.log 2>&1 || { cat cpack.log; fail "cpack -G DEB"; }
deb=$(ls mocap-graph_*_amd64.deb)
dpkg-deb -f "$deb" Depends | grep -q "libfastrtps2.9" ||
  fail "$deb: Depends lacks Fast DDS: $(dpkg-deb -f "$deb" Depends)"

"$scripts/make_debian_root.sh" "$root" || fail "no Debian 12 root"
cp "$deb" "$root/tmp/"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount -t proc proc "$root/proc"
mount --bind /dev "$root/dev"
chroot "$root" sh -c "apt-get update -q && DEBIAN_FRONTEND=noninteractive \
  apt-get install -y -q --no-install-recommends /tmp/$deb" > apt.log 2>&1 ||
  { tail -30 apt.log; fail "apt install ./$deb in a clean Debian 12 root"; }

domain=$((100 + $$ % 100))
chroot "$root" sh -c "cd /usr/share/mocap_graph && MOCAP_DOMAIN_ID=$domain \
  timeout 120 mocap_launch launch_yaml/mobile_mocap_demo.yaml --duration 5" > demo.log 2>&1 ||
  { cat demo.log; fail "mocap_launch from the installed package exited with $?"; }
poses=$(sed -n 's/.*\[pose\]: \([0-9]*\) poses published.*/\1/p' demo.log)
[ "${poses:-0}" -ge 100 ] || { cat demo.log; fail "only ${poses:-0} poses in 5 s"; }
grep -q "| 0 | 100.00 % |" demo.log || { cat demo.log; fail "not every frame tracked"; }
echo "PASS: $deb ($(du -h "$deb" | cut -f1)) installed by apt in a clean Debian 12 root; the demo published $poses poses"
