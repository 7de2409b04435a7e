#!/usr/bin/env bash
# scripts/remove_tree.sh never deletes through a mount: a root with a folder of ours bound into
# it as the Debian package's test binds /dev, the mount kept busy by a process inside it (so a
# plain umount fails, as it may in a test's cleanup), is removed while the bound folder keeps
# every file. Needs root (mount).
set -euo pipefail
remove_tree="$(cd "$(dirname "$0")/../.." && pwd)/scripts/remove_tree.sh"
work=$(mktemp -d)
holder=""
cleanup() {
  [ -z "$holder" ] || kill "$holder" 2> /dev/null || true
  umount --lazy "$work/root/dev" 2> /dev/null || true
  rm -rf --one-file-system "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

mkdir -p "$work/outside/sub" "$work/root/dev" "$work/root/etc"
echo kept > "$work/outside/sentinel"
echo kept > "$work/outside/sub/deeper"
echo gone > "$work/root/etc/file"
mount --bind "$work/outside" "$work/root/dev"
(cd "$work/root/dev" && exec sleep 60) &
holder=$!
sleep 0.2
! umount "$work/root/dev" 2> /dev/null || fail "the mount was not busy: the test proves nothing"

"$remove_tree" "$work/root" || fail "remove_tree.sh failed: $?"
[ ! -e "$work/root" ] || fail "$work/root is still there"
[ "$(cat "$work/outside/sentinel")" = kept ] || fail "a file of the bound folder was deleted"
[ "$(cat "$work/outside/sub/deeper")" = kept ] || fail "a file below the bound folder was deleted"
# Nothing to remove is no error.
"$remove_tree" "$work/root" || fail "remove_tree.sh of a missing folder failed"
echo "PASS: the root was removed, the folder bound into it kept both its files"
