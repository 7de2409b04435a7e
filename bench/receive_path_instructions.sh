#!/usr/bin/env bash
# Instructions a subscribing process spends per received message in its DDS listener call
# (taking, deserializing, delivering to the component), for the runtime and for raw Fast DDS
# with the same type and QoS. Counted by callgrind, so the figure is the same on every run
# and under any load, unlike the timings of transport_bench.
#
#   bench/receive_path_instructions.sh [BUILD_DIR]      (about half a minute)
#
# Each subscriber (transport_bench --subscriber) runs under callgrind against a paced
# publisher (the sequence_source test plugin), once for 200 and once for 1200 messages; the
# difference divided by 1000 is the cost of one message, without start-up and discovery.
set -euo pipefail
cd "$(dirname "$0")/.."
build=$(realpath "${1:-build}")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export MOCAP_PLUGIN_PATH="$build/test_plugins" MOCAP_DOMAIN_ID=$((200 + $$ % 30))

listener_instructions() {  # PATH COUNT
  cat > "$work/publisher.yaml" <<YAML
groups:
  - name: publisher
    components:
      - plugin: sequence_source
        name: source
        parameters: {count: $2, batch: 1, period_s: 0.005, subscribers: 1}
        remap: {/test/sequence: /bench/hop}
YAML
  (sleep 3; exec timeout 120 "$build/bin/mocap_launch" "$work/publisher.yaml" > /dev/null 2>&1) &
  local publisher=$!
  valgrind --tool=callgrind --callgrind-out-file="$work/$1_$2.out" \
    "$build/bin/transport_bench" --subscriber "$1" fiducials "$2" "$work/received" \
    > /dev/null 2>&1
  # The source publishes its count, then idles: stop it rather than wait for the timeout.
  kill -TERM "$publisher" 2>/dev/null || true
  wait
  local received
  received=$(awk 'NR == 1 {print $1}' "$work/received")
  if [ "$received" != "$2" ]; then
    echo "receive_path_instructions: $1 received $received of $2 messages" >&2
    exit 1
  fi
  # Fast DDS's own listener call, which wraps everything the message costs the receiver.
  callgrind_annotate --inclusive=yes "$work/$1_$2.out" > "$work/annotated"
  grep -m1 -E "on_data_available.*libfastrtps" "$work/annotated" |
    awk '{gsub(",", "", $1); print $1}'
}

declare -A per_message
for path in runtime raw; do
  few=$(listener_instructions "$path" 200)
  many=$(listener_instructions "$path" 1200)
  per_message[$path]=$(( (many - few) / 1000 ))
done
echo "receive_path_instructions: FiducialArray (12), reliable, instructions per received message"
echo
echo "| path                         | instructions | vs raw Fast DDS |"
echo "|------------------------------|--------------|-----------------|"
printf "| %-28s | %12d | %15s |\n" "raw Fast DDS (listener take)" "${per_message[raw]}" "1.00"
printf "| %-28s | %12d | %15s |\n" "runtime (subscription)" "${per_message[runtime]}" \
  "$(awk -v a="${per_message[runtime]}" -v b="${per_message[raw]}" 'BEGIN {printf "%.2f", a / b}')"
