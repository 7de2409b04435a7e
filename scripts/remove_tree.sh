#!/usr/bin/env bash
# Removes DIR and everything in it, never through a mount: whatever is mounted at or below DIR
# (a chroot's /proc, the host's /dev bound into it) is unmounted first, deepest first, and if
# anything is still mounted there afterwards nothing is removed and the exit status is 1. Even
# then, rm stays on DIR's own file system (--one-file-system).
#
#   scripts/remove_tree.sh DIR
set -euo pipefail
dir="${1:?usage: remove_tree.sh DIR}"
[ -e "$dir" ] || exit 0
dir=$(realpath "$dir")
# Mount points at or below DIR, deepest first (mountinfo's 5th field; octal escapes such as
# \040 for a space are decoded).
mounts_below() {
  awk -v dir="$dir" '{ print $5 }' /proc/self/mountinfo | while read -r point; do
    point=$(printf '%b' "$point")
    if [[ "$point" == "$dir" || "$point" == "$dir"/* ]]; then echo "$point"; fi
  done | sort -r
}
while read -r point; do
  [ -n "$point" ] || continue
  umount "$point" 2> /dev/null || umount --lazy "$point" 2> /dev/null || true
done <<< "$(mounts_below)"
still=$(mounts_below)
if [ -n "$still" ]; then
  echo "remove_tree.sh: $(head -1 <<< "$still") is still mounted; $dir is left in place" >&2
  exit 1
fi
rm -rf --one-file-system "$dir"
