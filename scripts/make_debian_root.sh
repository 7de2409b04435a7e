#!/usr/bin/env bash
# Makes a minimal Debian 12 root in DIR (debootstrap --variant=minbase) from this machine's
# Debian mirror, for the Debian package's test and the container test's base images.
#
#   scripts/make_debian_root.sh [--slim] DIR
#
# --slim: as Docker's debian:bookworm-slim is made: dpkg leaves documentation, manual pages
# and translations out of every package installed later, those already there are removed, and
# apt keeps no downloaded packages and no package lists.
set -euo pipefail
slim=0
if [ "${1:-}" = "--slim" ]; then
  slim=1
  shift
fi
root="${1:?usage: make_debian_root.sh [--slim] DIR}"
# debootstrap runs once a week: its root is kept as a tar file outside the clone
# (MOCAP_CACHE_DIR, default /var/cache/mocap-graph) and unpacked for every later use.
cache=${MOCAP_CACHE_DIR:-/var/cache/mocap-graph}/debian-bookworm-minbase.tar
if [ -n "$(find "$cache" -mtime -7 2> /dev/null)" ]; then
  mkdir -p "$root"
  tar -C "$root" -xf "$cache"
else
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
  if mkdir -p "$(dirname "$cache")" 2> /dev/null; then
    tar -C "$root" -cf "$cache.$$" . && mv "$cache.$$" "$cache" || rm -f "$cache.$$"
  fi
fi
[ $slim -eq 1 ] || exit 0

cat > "$root/etc/dpkg/dpkg.cfg.d/slim" << 'DPKG'
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/man/*
path-exclude /usr/share/info/*
path-exclude /usr/share/locale/*
path-include /usr/share/locale/locale.alias
path-exclude /usr/share/groff/*
path-exclude /usr/share/lintian/*
DPKG
cat > "$root/etc/apt/apt.conf.d/slim" << 'APT'
APT::Keep-Downloaded-Packages "false";
DPkg::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/*.bin || true"; };
APT
find "$root/usr/share/doc" -mindepth 1 -not -name copyright -not -type d -delete
find "$root/usr/share/doc" -mindepth 1 -type d -empty -delete
rm -rf "$root/usr/share/man/"* "$root/usr/share/info/"* "$root/usr/share/groff/"* \
  "$root/usr/share/lintian/"*
find "$root/usr/share/locale" -mindepth 1 -maxdepth 1 -not -name locale.alias -exec rm -rf {} +
rm -rf "$root/var/lib/apt/lists/"* "$root/var/cache/apt/"*.bin
