#!/usr/bin/env bash
# The multi-host scenario in containers, with faults: the Docker counterpart of
# scripts/netns_scenario.sh --faults.
#
#   sudo scripts/docker_test.sh [IMAGE]
#
# IMAGE: test that image instead of building one (kept at the end). MOCAP_PACKAGE_BUILD: make the
# image's package with cpack in that build tree, already built (CI passes its plain tree),
# instead of a build of its own.
# Starts a Docker engine if none answers (and stops only that one at the end), makes the
# debian:bookworm and debian:bookworm-slim base images with debootstrap if they are missing (no
# registry is needed), builds the image (docker/Dockerfile, from the package its build stage
# would make, made here in build-image/ with the compiler cache) and checks it as a user would: at
# most 400 MB, runs as the user mocap, `mocap_launch launch_yaml/mobile_mocap_demo.yaml` in it
# publishes poses. Then starts docker/compose.yaml's four hosts and runs the phases:
#   start         poses reach the checker container; `mocap_topic list` in another container
#                 and `mocap_topic echo` on this machine (outside the containers) see them
#   crash_compute compute's mocap_launch is killed (SIGKILL) inside its container; Docker's
#                 restart policy brings the container back; poses resume
#   stall_compute compute's process is stopped (SIGSTOP): its HEALTHCHECK must turn unhealthy,
#                 and healthy again once it continues (SIGCONT); poses resume
#   link_compute  compute's link goes down for longer than the DDS lease (its veth, host side,
#                 as a pulled cable) and up again; poses resume
# After each phase every host is healthy, the other containers have not restarted, the robot
# follows the board again and the observer's evaluator evaluates poses. Prints a table (per
# phase: the check, pose arrays/s at the checker, the observer's frames/s, latency median and
# p99, frames lost, compute's restarts and health) and exits non-zero on any failed check.
# Everything it made (containers, network, image) is removed at the end, also on failure or
# Ctrl-C; the base images stay, as pulled ones would.
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
  "$root/scripts/remove_tree.sh" "$work"
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
# The Dockerfile's two bases, as a registry would give them: debian:bookworm for the build,
# debian:bookworm-slim (no documentation, manual pages or translations) for the image.
for tag in bookworm bookworm-slim; do
  docker image inspect "debian:$tag" > /dev/null 2>&1 && continue
  option=""
  [ $tag = bookworm-slim ] && option=--slim
  scripts/make_debian_root.sh $option "$work/rootfs" || fail "no Debian 12 root for debian:$tag"
  rm -rf "$work/rootfs/var/lib/apt/lists/"*
  tar -C "$work/rootfs" -c . | docker import - "debian:$tag" > /dev/null
  scripts/remove_tree.sh "$work/rootfs"
done

# --- image
if [ $# -eq 0 ]; then
  build_start=$SECONDS
  built_image=$image
  rm -rf build-image
  if [ -n "${MOCAP_PACKAGE_BUILD:-}" ]; then
    # CI: the package of the tree its tests just built (the same sources and warnings; cpack
    # strips the debug information either way), rather than a fourth build of the product.
    # The Dockerfile's own path (a tree without tests) is configured, which is where it could
    # differ.
    cmake -S . -B "$work/package-configure" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DMOCAP_BUILD_TESTS=OFF -DMOCAP_BUILD_BENCHMARKS=OFF -DMOCAP_WERROR=ON \
      > "$work/package.log" 2>&1 || { tail -40 "$work/package.log"; fail "configure without tests"; }
    { cmake --build "$MOCAP_PACKAGE_BUILD" --target mocap_runtime_package &&
      (cd "$MOCAP_PACKAGE_BUILD" && cpack -G DEB -D CPACK_COMPONENTS_ALL=runtime -B "$root/build-image"); } \
      >> "$work/package.log" 2>&1 || { tail -40 "$work/package.log"; fail "the package of $MOCAP_PACKAGE_BUILD"; }
    made="the package of $MOCAP_PACKAGE_BUILD/"
  else
    # The image's package is made as the Dockerfile's build stage makes it (scripts/package.sh
    # --runtime-only, warnings as errors), in a build folder of its own made afresh, so that what
    # that path builds is checked here; on this machine rather than in the container, so that
    # the compiler cache serves it.
    MOCAP_PACKAGE_DIR=build-image scripts/package.sh --runtime-only -DMOCAP_WERROR=ON \
      > "$work/package.log" 2>&1 || { tail -40 "$work/package.log"; fail "scripts/package.sh --runtime-only"; }
    made="scripts/package.sh --runtime-only"
  fi
  # The Dockerfile takes it as MOCAP_DEB.
  deb=$(ls build-image/mocap-graph_*_amd64.deb)
  build_args=(--build-arg "MOCAP_DEB=$deb")
  how="from $deb ($made, $((SECONDS - build_start)) s)"
  docker build -f docker/Dockerfile "${build_args[@]}" -t "$image" . > "$work/build.log" 2>&1 ||
    { tail -40 "$work/build.log"; fail "docker build"; }
  echo "image: $image built $how in $((SECONDS - build_start)) s"
fi
size_mb=$(($(docker image inspect -f '{{.Size}}' "$image") / 1000000))
echo "image: $image, $size_mb MB"
[ "$size_mb" -le 400 ] || fail "the image is $size_mb MB, over its 400 MB budget"
[ "$(docker run --rm --network none "$image" id -un)" = mocap ] ||
  fail "the image does not run as its user mocap"
# The shipped demo, as a user would run it (in-process DDS only: no network).
docker run --rm --network none "$image" mocap_launch launch_yaml/mobile_mocap_demo.yaml \
  --duration 5 > "$work/demo.log" 2>&1 || { tail -20 "$work/demo.log"; fail "the demo in the image"; }
poses=$(sed -n 's/.*\[boards\]: [0-9]* arrays: \([0-9]*\) poses.*/\1/p' "$work/demo.log")
[ "${poses:-0}" -ge 100 ] || { tail -20 "$work/demo.log"; fail "the demo in the image: ${poses:-0} poses in 5 s"; }
echo "image: docker run ... mocap_launch launch_yaml/mobile_mocap_demo.yaml --duration 5: $poses poses"

# --- phases
rows=()
failed=0
restarts() { docker inspect -f '{{.RestartCount}}' "$(container "$1")"; }
health() { docker inspect -f '{{.State.Health.Status}}' "$(container "$1")"; }
# True once HOST's HEALTHCHECK reports STATUS (waits at most S seconds).
wait_health() {  # HOST STATUS S
  local deadline=$((SECONDS + $3))
  until [ "$(health "$1")" = "$2" ]; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 1
  done
}
check() {  # TIMEOUT COUNT -> check_line, status
  check_line=$(compose run --rm -T checker scenario.sh check --timeout "$1" --count "$2" 2>&1 | grep -m1 '^check: ' || true)
  [[ $check_line == "check: PASS"* ]]
}
# True once the last line of HOST's log that matches SELECT matches WANT too (waits 15 s).
log_says() {  # HOST SELECT WANT
  local deadline=$((SECONDS + 15)) last
  while :; do
    last=$(docker logs "$(container "$1")" 2>&1 | grep -E "$2" | tail -n 1 || true)
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
  local unhealthy=""
  for h in sensor compute robot observer; do
    wait_health "$h" healthy 30 || unhealthy+="$h "
  done
  if [ -n "$unhealthy" ]; then verdict=FAIL why+=" unhealthy: $unhealthy"; fi
  if ! log_says robot 'track of [A-Za-z0-9_]+ [a-z]+: ' ': following'; then
    verdict=FAIL why+=" the robot does not follow the board"
  fi
  # The observer's per-second lines during the phase: frames/s, latency median (the median
  # second's) and p99 (the worst second's), frames lost (summed).
  local stats
  stats=$(docker logs --since "$((SECONDS - since + 2))s" "$(container observer)" 2>&1 |
    sed -n 's/.*\[evaluator\]: \([0-9.]*\) frames\/s, latency \([0-9.a-z]*\) ms (p99 \([0-9.a-z]*\) ms), \([0-9]*\) frame.*/\1 \2 \3 \4/p' |
    awk '{ n++; f += $1; lost += $4 }  # seconds without poses have latency "nan"
      $2 != "nan" { l[++m] = $2; if ($3 > p99) p99 = $3 }
      END {
        if (m == 0) { print "- - - -"; exit }
        for (i = 2; i <= m; i++) for (j = i; j > 1 && l[j - 1] > l[j]; j--) {
          t = l[j]; l[j] = l[j - 1]; l[j - 1] = t
        }
        printf "%.1f %.2f %.2f %d\n", f / n, l[int((m + 1) / 2)], p99, lost }')
  if [ "$stats" = "- - - -" ]; then verdict=FAIL why+=" the observer evaluates no poses"; fi
  local rate
  rate=$(sed -n 's/^check: PASS \([0-9]*\) of [0-9]* .* in \([0-9.]*\) s;.*/\1 \2/p' <<< "$check_line" |
    awk '{ if ($2 > 0) printf "%.1f", $1 / $2; else print "-" }')
  read -r fps median p99 lost <<< "$stats"
  rows+=("| $name | $verdict | ${rate:--} | $fps | $median | $p99 | $lost | $(restarts compute) | $(health compute) |")
  echo "phase $name: $verdict ${why:-$check_line}"
  [ $verdict = PASS ] || failed=$((failed + 1))
}

compose up -d --no-build sensor compute robot observer > "$work/up.log" 2>&1 ||
  { cat "$work/up.log"; fail "docker-compose up"; }
declare -A start_restarts
snapshot() { for h in sensor compute robot observer; do start_restarts[$h]=$(restarts "$h"); done; }
snapshot
phase start none

# The image's mocap_topic on the compose network, as a user would look at a running graph.
docker run --rm --network "${project}_mocap" "$image" mocap_topic list --wait 5 \
  > "$work/list.log" 2>&1 || { cat "$work/list.log"; fail "mocap_topic list in a container"; }
grep -q '/mocap/poses' "$work/list.log" || { cat "$work/list.log"; fail "mocap_topic list in a container does not see /mocap/poses"; }
echo "outside: mocap_topic list in another container sees $(grep -c '^/' "$work/list.log") topics"
# A subscriber outside the containers: this machine, which is the compose network's gateway
# (its bridge interface), with the tree's own mocap_topic.
if [ -x "$root/build/bin/mocap_topic" ]; then
  timeout 60 "$root/build/bin/mocap_topic" echo /mocap/poses --count 5 > "$work/echo.log" 2>&1 ||
    { tail -5 "$work/echo.log"; fail "mocap_topic echo on the machine got no poses from the containers"; }
  echo "outside: mocap_topic echo on the machine received $(grep -c '^header:' "$work/echo.log") pose arrays"
else
  fail "no $root/build/bin/mocap_topic to subscribe from outside the containers (build the tree first: scripts/test.sh)"
fi

snapshot
# Crash: SIGKILL the host's process inside its container, as a crash would end it. (docker
# kill would be a manual stop, which the restart policy leaves stopped.)
docker exec "$(container compute)" sh -c 'kill -KILL $(cat /proc/1/task/1/children)'
for _ in $(seq 30); do [ "$(restarts compute)" -ge 1 ] && break; sleep 1; done
[ "$(restarts compute)" -ge 1 ] || fail "compute was not restarted after its crash"
phase crash_compute compute

snapshot
# Stall: compute's process stops (SIGSTOP) without dying; only the HEALTHCHECK can tell. It must
# say unhealthy, and healthy again once the process continues.
docker exec "$(container compute)" sh -c 'kill -STOP $(cat /proc/1/task/1/children)'
stalled=$SECONDS
if wait_health compute unhealthy 60; then
  echo "stall: compute's HEALTHCHECK says unhealthy $((SECONDS - stalled)) s after its process stopped"
else
  echo "phase stall_compute: compute stalled but its HEALTHCHECK says $(health compute)"
  failed=$((failed + 1))
fi
docker exec "$(container compute)" sh -c 'kill -CONT $(cat /proc/1/task/1/children)'
phase stall_compute none

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
echo "| phase | verdict | pose arrays/s at the checker | observer frames/s | latency median ms | latency p99 ms (worst second) | frames lost | compute restarts | compute health |"
echo "|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
[ $failed -eq 0 ] || fail "$failed check(s) failed"
echo "result: PASS"
