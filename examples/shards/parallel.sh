#!/usr/bin/env bash
# Simulate a model as N shards with GNU parallel, then assemble the whole result from the cache.
#
#   examples/shards/parallel.sh MODEL.ifc N CACHE_DIR [simulate options…]
#
# Each shard simulates the walls whose content key falls in it and stores them in CACHE_DIR;
# the last, plain `simulate` finds every wall there and prints the report. On a batch scheduler
# run the same shard command once per array index (see README, "Shards") with CACHE_DIR on a
# shared filesystem. FRAMEWRIGHT names the binary (default: framewright on PATH).
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 MODEL.ifc N CACHE_DIR [simulate options…]" >&2
  exit 2
fi
model=$1
shards=$2
cache=$3
shift 3
fw=${FRAMEWRIGHT:-framewright}
parallel --halt now,fail=1 "$fw" simulate "$model" --cache "$cache" --shard {}/"$shards" "$@" \
  ::: $(seq 1 "$shards") >&2
"$fw" simulate "$model" --cache "$cache" "$@"
