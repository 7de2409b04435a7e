# Hosts as network namespaces on one machine, joined by a Linux bridge in a namespace of its
# own, as hosts on a switch: sourced by the multi-host scenarios (scripts/netns_scenario.sh,
# scripts/netns_volume.sh). Needs root.
#
# Before sourcing, the scenario sets `hosts` (names), `address` (host -> IPv4 in one /24),
# `logs_out` (a directory to keep the logs in, or empty) and defines say(). Sourcing makes the
# network (exit 77 when it cannot) and gives: ns HOST (its namespace), on HOST COMMAND... (run
# in it, replacing the subshell), run COMMAND... (in the background, waited for, so signals are
# handled at once), alive HOST, link_bytes HOST rx|tx, the `pid` of each started host's process,
# `run_dir` for logs, and finish (the traffic, each host's last lines when a phase failed, the
# result; the scenario counts its phases in `passed` and `failed`). Everything is named mgtest_<pid>_* and removed when the script ends,
# however it ends.
if [ "$(id -u)" -ne 0 ]; then
  say "cannot make network namespaces: not root"
  exit 77
fi
for tool in ip timeout unshare; do
  command -v "$tool" >/dev/null || { say "cannot make network namespaces: no '$tool'"; exit 77; }
done

prefix="mgtest_$$"
net_ns="${prefix}_net"
ns() { echo "${prefix}_$1"; }
run_dir="$(mktemp -d "/tmp/${prefix}.XXXXXX")"
declare -A pid=()
made_ns=()
child=""  # a foreground command in progress (check, sleep), stopped by the cleanup

# Stops what runs, deletes the namespaces (and with them the links and the bridge), removes
# the run's files. Runs on every exit.
# shellcheck disable=SC2317  # (called by the EXIT trap)
cleanup() {
  local code=$?
  trap - EXIT INT TERM
  [ -n "$child" ] && kill -TERM "$child" 2>/dev/null
  local h
  for h in "${!pid[@]}"; do kill -TERM "${pid[$h]}" 2>/dev/null; done
  local deadline=$((SECONDS + 10))
  for h in "${!pid[@]}"; do
    while kill -0 "${pid[$h]}" 2>/dev/null && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.1; done
    kill -KILL "${pid[$h]}" 2>/dev/null
    wait "${pid[$h]}" 2>/dev/null
  done
  local n
  for n in "${made_ns[@]}"; do ip netns del "$n" 2>/dev/null; done
  if [ -n "$logs_out" ]; then
    mkdir -p "$logs_out" && cp "$run_dir"/*.log "$logs_out"/ 2>/dev/null
  fi
  rm -rf "$run_dir"
  exit "$code"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Runs a command in the background and waits for it, so a signal to this script is handled
# at once (bash runs traps only between commands); returns its status.
run() {
  "$@" &
  child=$!
  wait "$child"
  local code=$?
  child=""
  return $code
}

setup_fail() {
  say "cannot make network namespaces: $*"
  exit 77
}

# Runs a command on a host: in its network namespace, with a /dev/shm of its own as a real
# host has (no DDS shared memory with the other hosts or with anything else on this machine).
# Called in a subshell only (`on ... &`, `(on ...)`), which it replaces: ip netns exec,
# unshare and sh all exec too, so $! is the command's own process id.
on() {
  local h="$1"
  shift
  exec ip netns exec "$(ns "$h")" unshare --mount --propagation private \
    sh -c 'mount -t tmpfs -o size=256m,mode=1777 mgtest_shm /dev/shm && exec "$@"' sh "$@"
}

# The network: a bridge in its own namespace (the switch), one veth per host, the host's end
# named eth0. Multicast snooping off: the bridge floods multicast to every port, so DDS
# discovery works without an IGMP querier.
ip netns add "$net_ns" 2>"$run_dir/err" || setup_fail "ip netns add: $(cat "$run_dir/err")"
made_ns+=("$net_ns")
ip -n "$net_ns" link set lo up || setup_fail "lo up in $net_ns"
ip -n "$net_ns" link add br0 type bridge mcast_snooping 0 || setup_fail "bridge"
ip -n "$net_ns" link set br0 up || setup_fail "bridge up"
for h in "${hosts[@]}"; do
  n="$(ns "$h")"
  ip netns add "$n" || setup_fail "ip netns add $n"
  made_ns+=("$n")
  ip link add eth0 netns "$n" type veth peer name "$h" netns "$net_ns" ||
    setup_fail "veth for $h"
  ip -n "$net_ns" link set "$h" master br0 || setup_fail "$h into the bridge"
  ip -n "$net_ns" link set "$h" up || setup_fail "$h up"
  ip -n "$n" link set lo up || setup_fail "lo up in $n"
  ip -n "$n" addr add "${address[$h]}/24" dev eth0 || setup_fail "address of $h"
  ip -n "$n" link set eth0 up || setup_fail "eth0 up in $n"
  # DDS discovery is multicast; the namespace has no default route.
  ip -n "$n" route add 224.0.0.0/4 dev eth0 || setup_fail "multicast route in $n"
done
# Each host gets a /dev/shm of its own (on(), below): that must work here too.
(on "${hosts[0]}" true) 2>"$run_dir/err" || setup_fail "a private /dev/shm: $(cat "$run_dir/err")"
summary=""
for h in "${hosts[@]}"; do summary+="$h ${address[$h]}, "; done
say "hosts up: ${summary%, } on a bridge (namespaces ${prefix}_*; logs in $run_dir)"

alive() { kill -0 "${pid[$1]}" 2>/dev/null; }
link_bytes() { ip netns exec "$(ns "$1")" cat "/sys/class/net/eth0/statistics/$2_bytes" 2>/dev/null || echo 0; }

# Ends the run: each host's traffic, their logs' last lines when a phase failed, the result.
passed=0 failed=0
finish() {
  local h traffic=""
  for h in "${hosts[@]}"; do
    traffic+="$h rx $(($(link_bytes "$h" rx) / 1024)) KiB tx $(($(link_bytes "$h" tx) / 1024)) KiB; "
  done
  echo "traffic: ${traffic%; }"
  if [ $failed -gt 0 ]; then
    for h in "${hosts[@]}"; do
      echo "--- last lines of $h's log ---"
      tail -n 15 "$run_dir/$h.log" 2>/dev/null
    done
    echo "result: FAIL $failed of $((passed + failed)) phases failed"
    exit 1
  fi
  echo "result: PASS $passed of $passed phases"
  exit 0
}
