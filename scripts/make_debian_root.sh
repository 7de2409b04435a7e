#!/usr/bin/env bash
# Makes a minimal Debian 12 root in DIR (debootstrap --variant=minbase) from this machine's
# Debian mirror, for the Debian package's test and the container test's base image.
#
#   scripts/make_debian_root.sh DIR
set -euo pipefail
root="${1:?usage: make_debian_root.sh DIR}"
mirror=$(sed -n 's/^URIs: *//p' /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -1)
log=$(mktemp)
if ! debootstrap --variant=minbase bookworm "$root" "${mirror:-http://deb.debian.org/debian}" \
  > "$log" 2>&1; then
  tail -20 "$log" >&2
  rm -f "$log"
  echo "make_debian_root.sh: debootstrap into $root failed" >&2
  exit 1
fi
rm -f "$log"
