#!/usr/bin/env bash
# A vademecum build split in N shards run at once as local processes, then merged, against
# the whole build in the same run:
#   scripts/bench-shards.sh [SHARD COUNTS] [PGD BUILD ARGUMENTS...]
# e.g. scripts/bench-shards.sh "1 2 4" liver. Each shard process gets the machine's cores
# shared out (RAYON_NUM_THREADS = cores / N, at least 1), as N machines would each have theirs;
# on a machine with fewer cores than shards they queue. Prints one JSON object: the whole
# build's seconds, and per count the shards' wall seconds, the merge's, their sum, its ratio
# to the whole build, and the parts' bytes. (That the merged file equals the whole build's is
# what `cargo test --test commands shards` checks.)
set -euo pipefail
counts=${1:-"1 2 4"}
shift || true
[ $# -gt 0 ] || set -- liver
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cargo build --release --bin pgd --manifest-path "$root/Cargo.toml" >&2
pgd="$root/target/release/pgd"
cores=$(nproc)
now() { date +%s.%N; }
seconds() { echo "$2 - $1" | bc; }

start=$(now)
"$pgd" build "$@" --out "$work/whole.vdm" >/dev/null 2>&1
whole=$(seconds "$start" "$(now)")
runs=()
for n in $counts; do
  threads=$(( cores / n > 0 ? cores / n : 1 ))
  start=$(now)
  for k in $(seq 1 "$n"); do
    RAYON_NUM_THREADS=$threads "$pgd" build "$@" --out "$work/s$n.vdm" --shard "$k/$n" >/dev/null 2>&1 &
  done
  wait
  middle=$(now)
  "$pgd" merge "$work"/s$n.part-*-of-$n.vdp --out "$work/merged$n.vdm" >/dev/null 2>&1
  end=$(now)
  shards=$(seconds "$start" "$middle")
  merge=$(seconds "$middle" "$end")
  total=$(seconds "$start" "$end")
  part_bytes=$(cat "$work"/s$n.part-*-of-$n.vdp | wc -c)
  runs+=("{\"shards\": $n, \"threads_each\": $threads, \"shards_seconds\": $shards, \"merge_seconds\": $merge, \"total_seconds\": $total, \"ratio_to_whole\": $(echo "scale=3; $total / $whole" | bc), \"parts_bytes\": $part_bytes}")
done
printf '{"arguments": "%s", "cores": %d, "whole_seconds": %s, "runs": [%s]}\n' \
  "$*" "$cores" "$whole" "$(IFS=,; echo "${runs[*]}")"
