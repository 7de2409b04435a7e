#!/bin/sh
# A container's HEALTHCHECK (docker/Dockerfile): healthy while mocap_launch keeps rewriting its
# health file, MOCAP_HEALTH_FILE (and FILE.GROUP for each group of a several-group launch
# file), that is while its executor still runs callbacks. Prints one line; exits 0 or 1.
#
#   healthcheck.sh [MAX_AGE_S]    (default 5: the files are rewritten every second)
file="${MOCAP_HEALTH_FILE:?healthcheck.sh: MOCAP_HEALTH_FILE is not set}"
max_age="${1:-5}"
now=$(date +%s)
found=0
for f in "$file" "$file".*; do
  [ -f "$f" ] || continue
  case "$f" in *.partial) continue ;; esac
  found=1
  age=$((now - $(stat -c %Y "$f")))
  if [ "$age" -gt "$max_age" ]; then
    echo "unhealthy: $f last rewritten ${age} s ago (more than ${max_age} s)"
    exit 1
  fi
done
if [ "$found" -eq 0 ]; then
  echo "unhealthy: no health file $file (is mocap_launch running?)"
  exit 1
fi
echo "healthy: $(cat "$file" "$file".* 2>/dev/null | grep -c alive) process(es) alive"
