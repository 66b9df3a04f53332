#!/usr/bin/env bash
# Tiled erosion at 4097² on 1, 2 and 4 ranks (docs/benchmarks.md, "MPI").
# usage: tests/bench/mpi_scaling.sh [BUILD_DIR] [REPEATS] [thermal|pipe|hydraulic|stream-power] [SIZE]
# Prints, per configuration and repetition: the eroder's seconds (rank 0's
# timing table), rank 0's info line (its time in the steps, the halo exchange,
# for pipe the cross-rank reductions, and the wait for the other ranks), every
# rank's peak RSS and the CPU seconds of all ranks, with the load average.
set -euo pipefail
build=${1:-build}
reps=${2:-3}
node=${3:-thermal}
size=${4:-4097}
orogen=$(realpath "$build/bin/orogen")
cell=1 base='f = generate:fault(iterations=200, displacement=0.5)'
# Stream power on diamond-square relief at 30 m (the default pipeline's ground): fault relief that flat is one vast lake.
[ "$node" = stream-power ] && cell=30 base='f = generate:diamond-square(roughness=0.6, amplitude=250)'
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
case "$node" in
  thermal) step='t = erode:thermal(f, talus=30, rate=0.5, iterations=64)'; kind=erode:thermal ;;
  # 6 steps of 0.25 s: 12 CFL sub-steps at 4097² (the count is the same on any number of ranks).
  pipe) step='t = erode:pipe(f, steps=6, dt=0.25, rain=0.001)'; kind=erode:pipe ;;
  hydraulic) step='t = erode:hydraulic(f, iterations=16)'; kind=erode:hydraulic ;;
  # 4 steps of 10 kyr: routing (thousands of pits in the first step), diffusion, incision.
  stream-power) step='t = erode:stream-power(f, years=4e4, dt=1e4, diffusivity=0.01)'; kind=erode:stream-power ;;
  *) echo "unknown node $node (thermal, pipe, hydraulic or stream-power)" >&2; exit 2 ;;
esac
cat >"$work/spec.orogen" <<SPEC
orogen 1
seed 1
grid $size cell=$cell

$base
$step
SPEC
mpirun=(mpirun --oversubscribe --allow-run-as-root)
one() {  # label, command...
  local label=$1; shift
  for r in $(seq "$reps"); do
    rm -rf "$work/out"
    local load
    load=$(cut -d' ' -f1-3 /proc/loadavg)
    "$@" run "$work/spec.orogen" --out "$work/out" --threads 1 --no-cache >"$work/log" 2>&1
    local t info rss cpu
    t=$(awk -v k="$kind" '$2==k{print $4}' "$work/log")
    info=$(grep -o 'rank 0 of [0-9]*[:,] .*' "$work/log" | head -1 || true)
    rss=$(grep 'Maximum resident' "$work/log" | awk '{printf "%d ", $6/1024}')
    # CPU seconds (user + system) summed over the ranks: what the run costs whatever the machine's load.
    cpu=$(awk '/User time/{u+=$4} /System time/{s+=$4} END{printf "%.2f", u+s}' "$work/log")
    echo "$label rep $r (load $load): $node ${t} s; ${info:-single process}; peak RSS MiB per rank: $rss; CPU s (all ranks, whole run): $cpu"
  done
}
one "1 process (no mpirun)" /usr/bin/time -v "$orogen"
one "mpirun -n 1" "${mpirun[@]}" -n 1 /usr/bin/time -v "$orogen"
one "mpirun -n 2" "${mpirun[@]}" -n 2 /usr/bin/time -v "$orogen"
one "mpirun -n 4" "${mpirun[@]}" -n 4 /usr/bin/time -v "$orogen"
