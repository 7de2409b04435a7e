#!/usr/bin/env bash
# The multi-host scenario in containers, with faults: the Docker counterpart of
# scripts/netns_scenario.sh --faults.
#
#   sudo scripts/docker_test.sh [IMAGE]
#
# IMAGE: test that image instead of building one (kept at the end).
# Starts a Docker engine if none answers (and stops only that one at the end), makes the
# debian:bookworm base image with debootstrap if it is missing (no registry is needed), builds
# the image (docker/Dockerfile), starts docker/compose.yaml's four hosts, then:
#   start         poses reach the checker container
#   crash_compute compute's mocap_launch is killed (SIGKILL) inside its container; Docker's
#                 restart policy brings the container back; poses resume
#   link_compute  compute's link goes down for longer than the DDS lease (its veth, host side,
#                 as a pulled cable) and up again; poses resume
# After each fault the other containers must not have restarted, the robot must follow the
# board again and the observer's evaluator must evaluate poses. Prints a table (per phase: the
# check, pose arrays/s at the checker, the observer's frames/s and latency median/max, and
# restarts) and exits non-zero on any failed check. Everything it made (containers, network,
# image) is removed at the end, also on failure or Ctrl-C.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
project="mocaptest$$"
image="${1:-mocap-graph:test-$$}"
built_image=""
work=$(mktemp -d /tmp/mocap_docker_test.XXXXXX)
dockerd_pid=""
export MOCAP_IMAGE=$image COMPOSE_PROJECT_NAME=$project MOCAP_DOMAIN_ID=${MOCAP_DOMAIN_ID:-0}
compose() { docker-compose -f "$root/docker/compose.yaml" "$@"; }
container() { echo "${project}_$1_1"; }

cleanup() {
  local status=$?
  trap - EXIT INT TERM
  if docker info > /dev/null 2>&1; then
    if [ $status -ne 0 ]; then
      for h in sensor compute robot observer; do
        echo "--- last lines of $h ---"
        docker logs --tail 10 "$(container "$h")" 2>&1 || true
      done
    fi
    compose down --volumes --remove-orphans > /dev/null 2>&1 || true
    if [ -n "$built_image" ]; then
      docker image rm -f "$built_image" > /dev/null 2>&1 || true
      docker image prune -f --filter label=org.mocap-graph.stage=build > /dev/null 2>&1 || true
    fi
  fi
  if [ -n "$dockerd_pid" ]; then
    kill "$dockerd_pid" 2>/dev/null || true
    wait "$dockerd_pid" 2>/dev/null || true
  fi
  rm -rf "$work"
  exit $status
}
trap cleanup EXIT
trap 'exit 130' INT TERM
fail() { echo "FAIL: $*" >&2; exit 1; }

# --- engine and base image
if ! docker info > /dev/null 2>&1; then
  command -v dockerd > /dev/null || fail "no Docker engine answers and dockerd is not installed (apt-get install docker.io)"
  dockerd > "$work/dockerd.log" 2>&1 &
  dockerd_pid=$!
  for _ in $(seq 60); do docker info > /dev/null 2>&1 && break; sleep 0.5; done
  docker info > /dev/null 2>&1 || { tail -20 "$work/dockerd.log"; fail "dockerd did not start"; }
fi
if ! docker image inspect debian:bookworm > /dev/null 2>&1; then
  scripts/make_debian_root.sh "$work/rootfs" || fail "no Debian 12 root for the base image"
  rm -rf "$work/rootfs/var/lib/apt/lists/"*
  tar -C "$work/rootfs" -c . | docker import - debian:bookworm > /dev/null
  rm -rf "$work/rootfs"
fi
docker image inspect debian:bookworm-slim > /dev/null 2>&1 || docker tag debian:bookworm debian:bookworm-slim

# --- image
if [ $# -eq 0 ]; then
  build_start=$SECONDS
  built_image=$image
  docker build -f docker/Dockerfile -t "$image" . > "$work/build.log" 2>&1 ||
    { tail -40 "$work/build.log"; fail "docker build"; }
  echo "image: $image built in $((SECONDS - build_start)) s"
fi
echo "image: $image, $(($(docker image inspect -f '{{.Size}}' "$image") / 1000000)) MB"

# --- phases
rows=()
failed=0
restarts() { docker inspect -f '{{.RestartCount}}' "$(container "$1")"; }
check() {  # TIMEOUT COUNT -> check_line, status
  check_line=$(compose run --rm -T checker check --timeout "$1" --count "$2" 2>&1 | grep -m1 '^check: ' || true)
  [[ $check_line == "check: PASS"* ]]
}
# True once the last line of HOST's log that matches SELECT matches WANT too (waits 15 s).
log_says() {  # HOST SELECT WANT
  local deadline=$((SECONDS + 15)) last
  while :; do
    last=$(docker logs --since 5s "$(container "$1")" 2>&1 | grep -E "$2" | tail -n 1 || true)
    grep -qE "$3" <<< "$last" && return 0
    [ $SECONDS -lt $deadline ] || return 1
    sleep 1
  done
}
phase() {  # NAME EXEMPT_HOST
  local name=$1 exempt=$2 verdict=PASS why="" since=$SECONDS
  if ! check 60 90; then
    verdict=FAIL why="$check_line"
  fi
  local others=""
  for h in sensor compute robot observer; do
    [ "$h" = "$exempt" ] && continue
    [ "$(restarts "$h")" = "${start_restarts[$h]}" ] || others+="$h "
  done
  if [ -n "$others" ]; then verdict=FAIL why+=" restarted: $others"; fi
  if ! log_says robot 'track of [A-Za-z0-9_]+ [a-z]+: ' ': following'; then
    verdict=FAIL why+=" the robot does not follow the board"
  fi
  # The observer's per-second lines during the check: frames/s and latency.
  local stats
  stats=$(docker logs --since "$((SECONDS - since + 2))s" "$(container observer)" 2>&1 |
    sed -n 's/.*\[evaluator\]: \([0-9.]*\) frames\/s, latency \([0-9.]*\) ms.*/\1 \2/p' |
    sort -k2 -g | awk '{ f[NR] = $1; l[NR] = $2 } END {
      if (NR == 0) { print "- - -"; exit }
      fs = 0; for (i = 1; i <= NR; i++) fs += f[i]
      printf "%.1f %.2f %.2f\n", fs / NR, l[int((NR + 1) / 2)], l[NR] }')
  if [ "$stats" = "- - -" ]; then verdict=FAIL why+=" the observer evaluates no poses"; fi
  local rate
  rate=$(sed -n 's/^check: PASS \([0-9]*\) of [0-9]* .* in \([0-9.]*\) s;.*/\1 \2/p' <<< "$check_line" |
    awk '{ if ($2 > 0) printf "%.1f", $1 / $2; else print "-" }')
  read -r fps median max <<< "$stats"
  rows+=("| $name | $verdict | ${rate:--} | $fps | $median | $max | $(restarts compute) |")
  echo "phase $name: $verdict ${why:-$check_line}"
  [ $verdict = PASS ] || failed=$((failed + 1))
}

compose up -d --no-build sensor compute robot observer > "$work/up.log" 2>&1 ||
  { cat "$work/up.log"; fail "docker-compose up"; }
declare -A start_restarts
snapshot() { for h in sensor compute robot observer; do start_restarts[$h]=$(restarts "$h"); done; }
snapshot
phase start none

snapshot
# Crash: SIGKILL the host's process inside its container, as a crash would end it. (docker
# kill would be a manual stop, which the restart policy leaves stopped.)
docker exec "$(container compute)" sh -c 'kill -KILL $(cat /proc/1/task/1/children)'
for _ in $(seq 30); do [ "$(restarts compute)" -ge 1 ] && break; sleep 1; done
[ "$(restarts compute)" -ge 1 ] || fail "compute was not restarted after its crash"
phase crash_compute compute

snapshot
# Link: down longer than the DDS lease (netns_scenario.sh's 7 s), then up. The container's
# eth0 is one end of a veth pair; the host's end goes down, as a pulled cable would. (docker
# network disconnect removes eth0 itself: Fast DDS 2.9 then never receives multicast on the
# interface that replaces it, and the host stays cut off.)
peer=$(docker exec "$(container compute)" cat /sys/class/net/eth0/iflink)
veth=$(ip -o link | awk -F': ' -v ifindex="$peer" '$1 == ifindex { sub(/@.*/, "", $2); print $2 }')
[ -n "$veth" ] || fail "no host-side veth of compute (ifindex $peer)"
ip link set "$veth" down
sleep 7
if check 5 5; then
  echo "phase link_compute: poses still arrived while compute's link was down ($check_line)"
  failed=$((failed + 1))
fi
ip link set "$veth" up
phase link_compute none

echo
echo "| phase | verdict | pose arrays/s at the checker | observer frames/s | latency median ms | latency max ms | compute restarts |"
echo "|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
[ $failed -eq 0 ] || fail "$failed check(s) failed"
echo "result: PASS"
