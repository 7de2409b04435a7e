#!/usr/bin/env bash
# Runs COMMAND only on processor time nothing else wants: in a CPU cgroup of its own whose
# cpu.idle is 1, and in the scheduler's idle class inside it.
#
#   scripts/run_idle.sh COMMAND [ARGS...]
#
# The idle class alone (chrt --idle) yields only to processes of its own scheduling group. With
# autogroups (kernel.sched_autogroup_enabled, Debian's default) each session is a group, and a
# process that starts a session of its own (headless chromium, which playwright starts
# detached) then shares the processors with the idle-class compiler's whole session as with an
# equal: beside two idle-class busy loops the real-time tests took 222 s instead of 156 s and
# three of them failed (the turret at 16 Hz for 25, a tenth of the volume's frames short of a
# camera). A cgroup marked idle yields to every other group (Linux 5.15 and later): the same
# run, its loops in one, took 156 s and passed. Where no such cgroup can be made (no cpu
# controller, not root), COMMAND runs in the idle class alone, with a warning.
set -euo pipefail
[ $# -gt 0 ] || {
  echo "usage: scripts/run_idle.sh COMMAND [ARGS...]" >&2
  exit 2
}

# The cpu controller's root: cgroup v1's cpu hierarchy, else the unified one where it offers cpu.
cpu_root() {
  if [ -f /sys/fs/cgroup/cpu/cpu.idle ] || [ -f /sys/fs/cgroup/cpu/cpu.shares ]; then
    echo /sys/fs/cgroup/cpu
  elif grep -qw cpu /sys/fs/cgroup/cgroup.controllers 2> /dev/null; then
    # v2: the root's children get the cpu controller only once the root hands it down.
    grep -qw cpu /sys/fs/cgroup/cgroup.subtree_control ||
      echo +cpu > /sys/fs/cgroup/cgroup.subtree_control 2> /dev/null || return 1
    echo /sys/fs/cgroup
  else
    return 1
  fi
}

group=""
if root=$(cpu_root); then
  # Groups of runs that were killed before they could remove theirs (rmdir keeps busy ones).
  for stale in "$root"/mocap-idle-*; do
    [ -d "$stale" ] && rmdir "$stale" 2> /dev/null || true
  done
  candidate="$root/mocap-idle-$$"
  if mkdir "$candidate" 2> /dev/null &&
    echo 1 > "$candidate/cpu.idle" 2> /dev/null &&
    echo $$ > "$candidate/cgroup.procs" 2> /dev/null; then
    group=$candidate
  else
    rmdir "$candidate" 2> /dev/null || true
  fi
fi
if [ -z "$group" ]; then
  echo "run_idle.sh: no idle CPU cgroup here (cgroup cpu controller with cpu.idle, as root):" \
    "$1 runs in the idle class only, and may slow processes of other sessions" >&2
  exec chrt --idle 0 "$@"
fi

status=0
chrt --idle 0 "$@" || status=$?
# Out of the group, so that it can go.
echo $$ > "$root/cgroup.procs" 2> /dev/null || true
rmdir "$group" 2> /dev/null || true
exit $status
