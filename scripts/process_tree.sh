#!/usr/bin/env bash
# The processes of a process group and every process below them, which a signal to the group
# alone misses: ninja starts each compiler in a process group of its own, so `kill -STOP -PGID`
# stopped ninja while the compilers it had started ran on.
#
#   scripts/process_tree.sh SIGNAL PGID   sends SIGNAL (STOP, CONT, TERM...) to each of them,
#                                         again until no new one appears (a parent stopped
#                                         late may have started one)
#   scripts/process_tree.sh cpu PGID      the processor time they have used, in seconds (their
#                                         own and that of their children they have reaped;
#                                         a finished child not yet reaped still counts)
set -euo pipefail
what=${1:?usage: process_tree.sh SIGNAL|cpu PGID}
group=${2:?usage: process_tree.sh SIGNAL|cpu PGID}

# PIDs of the group's processes and of their descendants.
members() {
  ps -e -o pid=,ppid=,pgid= | awk -v group="$group" '
    { parent[$1] = $2; in_group[$1] = ($3 == group) }
    END {
      for (pid in parent) {
        for (p = pid; p in parent && p > 1; p = parent[p]) {
          if (in_group[p]) { print pid; break }
        }
      }
    }'
}

if [ "$what" = cpu ]; then
  ticks=0
  for pid in $(members); do
    # Fields 14-17 of /proc/PID/stat, counted after the command's closing parenthesis.
    stat=$(cat "/proc/$pid/stat" 2> /dev/null) || continue
    read -r -a fields <<< "${stat##*) }"
    ticks=$((ticks + fields[11] + fields[12] + fields[13] + fields[14]))
  done
  awk -v ticks="$ticks" -v hz="$(getconf CLK_TCK)" 'BEGIN { printf "%.1f\n", ticks / hz }'
  exit 0
fi
signalled=" "
for _ in 1 2 3 4 5; do
  new=0
  for pid in $(members); do
    [[ "$signalled" == *" $pid "* ]] && continue
    kill -"$what" "$pid" 2> /dev/null || true
    signalled+="$pid "
    new=1
  done
  [ $new = 1 ] || break
done
