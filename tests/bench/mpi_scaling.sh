#!/usr/bin/env bash
# Tiled thermal erosion at 4097² on 1, 2 and 4 ranks (docs/benchmarks.md, "MPI").
# usage: tests/bench/mpi_scaling.sh [BUILD_DIR] [REPEATS]
# Prints, per configuration and repetition: the thermal node's seconds (rank 0's
# timing table), rank 0's sweep / halo-exchange split and every rank's peak RSS.
set -euo pipefail
build=${1:-build}
reps=${2:-3}
orogen=$(realpath "$build/bin/orogen")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/thermal.orogen" <<'SPEC'
orogen 1
seed 1
grid 4097 cell=1

f = generate:fault(iterations=200, displacement=0.5)
t = erode:thermal(f, talus=30, rate=0.5, iterations=64)
SPEC
mpirun=(mpirun --oversubscribe --allow-run-as-root)
one() {  # label, command...
  local label=$1; shift
  for r in $(seq "$reps"); do
    rm -rf "$work/out"
    "$@" run "$work/thermal.orogen" --out "$work/out" --threads 1 >"$work/log" 2>&1
    local t ex rss
    t=$(awk '$2=="erode:thermal"{print $4}' "$work/log")
    ex=$(grep -o 'sweeps [0-9.e-]* s, halo exchange [0-9.e-]* s ([0-9.e-]* %), of which waiting for the other ranks [0-9.e-]* s' "$work/log" | head -1 || true)
    rss=$(grep 'Maximum resident' "$work/log" | awk '{printf "%d ", $6/1024}')
    # CPU seconds (user + system) summed over the ranks: what the run costs whatever the machine's load.
    cpu=$(awk '/User time/{u+=$4} /System time/{s+=$4} END{printf "%.2f", u+s}' "$work/log")
    echo "$label rep $r: thermal ${t} s; ${ex:-single process}; peak RSS MiB per rank: $rss; CPU s (all ranks, whole run): $cpu"
  done
}
one "1 process (no mpirun)" /usr/bin/time -v "$orogen"
one "mpirun -n 1" "${mpirun[@]}" -n 1 /usr/bin/time -v "$orogen"
one "mpirun -n 2" "${mpirun[@]}" -n 2 /usr/bin/time -v "$orogen"
one "mpirun -n 4" "${mpirun[@]}" -n 4 /usr/bin/time -v "$orogen"
