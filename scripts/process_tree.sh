#!/usr/bin/env bash
# The processes of a process group and every process below them, which a signal to the group
# alone misses: ninja starts each compiler in a process group of its own, so `kill -STOP -PGID`
# stopped ninja while the compilers it had started ran on.
#
#   scripts/process_tree.sh SIGNAL PGID   sends SIGNAL (TERM, STOP, CONT...) to each of them,
#                                         again until no new one appears (a parent signalled
#                                         late may have started one)
set -euo pipefail
what=${1:?usage: process_tree.sh SIGNAL PGID}
group=${2:?usage: process_tree.sh SIGNAL PGID}

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
