#!/usr/bin/env bash
# docs/processes.md's "A process of your own", step for step: its soil.cpp and CMakeLists.txt (which must be
# tests/kernel/external_process/, byte for byte), then its commands as written, in a scratch folder where
# `build` is this build tree and ~ a scratch home: the process built against the build tree and against an
# install, each loaded through OROGEN_PLUGIN_PATH. Then the default's terrain (on a 257² grid, 0.3 Myr) with
# soil in its loop: a soil layer, a terrain that differs from the loop without it, and the stability check.
set -euo pipefail
build=$1 source=$2 doc=$3 pipeline=$4 work=$5
rm -rf "$work"
mkdir -p "$work/home" "$work/soil"

# The first of the doc's fenced blocks with a line matching $1.
block() {
    awk -v want="$1" '
        /^```/ { if (inside) { if (hit) { printf "%s", text; exit } inside = 0; next } inside = 1; hit = 0; text = ""; next }
        inside { text = text $0 "\n"; if ($0 ~ want) hit = 1 }' "$doc"
}
block '^// soil.cpp' >"$work/soil/soil.cpp"
block '^# CMakeLists.txt' >"$work/soil/CMakeLists.txt"
block 'cmake -S soil' >"$work/steps.sh"
for f in soil.cpp CMakeLists.txt; do
    test -s "$work/soil/$f" || { echo "FAIL: the doc shows no $f"; exit 1; }
    cmp -s "$work/soil/$f" "$source/$f" ||
        { echo "FAIL: the doc's $f is not tests/kernel/external_process/$f:"; diff "$work/soil/$f" "$source/$f"; exit 1; }
done
lines=$(wc -l <"$source/soil.cpp")
[ "$lines" -le 80 ] || { echo "FAIL: soil.cpp is $lines lines, more than the 80 the tutorial promises"; exit 1; }

ln -s "$(cd "$build" && pwd)" "$work/build"
{ echo 'set -euo pipefail'; echo 'cd "$(dirname "$0")"'; sed -E 's/(orogen help soil)$/\1 | tee -a help.txt/' "$work/steps.sh"; } \
    >"$work/run-steps.sh"
HOME="$work/home" bash "$work/run-steps.sh" >"$work/steps.log" 2>&1 ||
    { echo "FAIL: the doc's steps failed:"; tail -40 "$work/steps.log"; exit 1; }
[ "$(grep -c '^process soil — soil produced from rock' "$work/help.txt")" = 2 ] ||
    { echo "FAIL: 'orogen help soil' did not describe the process twice"; cat "$work/steps.log"; exit 1; }

# The default's terrain, cut before its exports, on a smaller grid for a shorter time.
cut() {  # cut SOIL_LINE > spec
    awk -v soil="$1" '/^export:png\(soil/ { exit } { print } /^    creep\(/ && soil != "" { print soil }' "$pipeline" |
        sed -e 's/^grid 1025 /grid 257 /' -e 's/years=3e6/years=3e5/'
    echo 'export:raw(range, path="range.r32")'
    echo 'export:vtk(range, path="range.vti")'
}
cut "" >"$work/plain.orogen"
cut '    soil(production=2e-4, depth=0.5, diffusivity=0.003)' >"$work/soil.orogen"
cut '    soil(production=2e-4, depth=0.5, diffusivity=0.01)' >"$work/unstable.orogen"
grep -q '^    soil(' "$work/soil.orogen" || { echo "FAIL: found no creep() in the default's loop to follow"; exit 1; }
for pair in "$build/bin/orogen:$work/soil/build" "$work/home/.local/bin/orogen:$work/soil/build-installed"; do
    orogen=${pair%%:*} plugin=${pair#*:}
    rm -rf "$work/out-plain" "$work/out-soil"
    OROGEN_NO_CACHE=1 "$orogen" run "$work/plain.orogen" --out "$work/out-plain" --quiet
    OROGEN_NO_CACHE=1 OROGEN_PLUGIN_PATH="$plugin" "$orogen" run "$work/soil.orogen" --out "$work/out-soil" --quiet
    grep -q 'Name="soil"' "$work/out-soil/range.vti" || { echo "FAIL: $orogen: no soil layer in range.vti"; exit 1; }
    if cmp -s "$work/out-plain/range.r32" "$work/out-soil/range.r32"; then
        echo "FAIL: $orogen: the soil process changed nothing"; exit 1
    fi
done
set +e
err=$(OROGEN_PLUGIN_PATH="$work/soil/build" "$build/bin/orogen" check "$work/unstable.orogen" 2>&1)
code=$?
set -e
[ "$code" = 2 ] || { echo "FAIL: an unstable soil step was not refused (exit $code): $err"; exit 1; }
grep -q "soil: the sub-step dt/substeps = 60000 yr is longer than its stable step, 22500 yr on 30 m cells; give the node dt <= 22500 or substeps >= 3" <<<"$err" ||
    { echo "FAIL: the stability error is not the doc's: $err"; exit 1; }
echo "out-of-tree process: the doc's soil process built against the build tree and an install; it joins the default's loop"
