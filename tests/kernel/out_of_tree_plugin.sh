#!/usr/bin/env bash
# The README's "Write a plugin", step for step: its terrace.cpp and CMakeLists.txt
# (which must be tests/kernel/external_plugin/, byte for byte), then its shell
# commands as written, run in a scratch folder where `build` is this build tree
# and ~ a scratch home: the plugin built against the build tree (orogen_DIR) and
# against an install (CMAKE_PREFIX_PATH), each loaded through
# OROGEN_PLUGIN_PATH and run.
set -euo pipefail
build=$1 source=$2 readme=$3 work=$4
rm -rf "$work"
mkdir -p "$work/home" "$work/terrace"

# The first of the README's fenced blocks with a line matching $1.
block() {
    awk -v want="$1" '
        /^```/ { if (inside) { if (hit) { printf "%s", text; exit } inside = 0; next } inside = 1; hit = 0; text = ""; next }
        inside { text = text $0 "\n"; if ($0 ~ want) hit = 1 }' "$readme"
}
block '^// terrace.cpp' >"$work/terrace/terrace.cpp"
block '^# CMakeLists.txt' >"$work/terrace/CMakeLists.txt"
block 'cmake -S terrace' >"$work/steps.sh"
for f in terrace.cpp CMakeLists.txt; do
    test -s "$work/terrace/$f" || { echo "FAIL: the README shows no $f"; exit 1; }
    cmp -s "$work/terrace/$f" "$source/$f" ||
        { echo "FAIL: the README's $f is not tests/kernel/external_plugin/$f:"; diff "$work/terrace/$f" "$source/$f"; exit 1; }
done
grep -q 'orogen_DIR' "$work/steps.sh" || { echo "FAIL: the README does not build against the build tree"; exit 1; }
grep -q 'cmake --install' "$work/steps.sh" || { echo "FAIL: the README does not build against an install"; exit 1; }

# The steps as the README writes them, from a folder holding `build` and `terrace`. Each `orogen help` must
# describe the plugin's node.
ln -s "$(cd "$build" && pwd)" "$work/build"
cat >"$work/run-steps.sh" <<'STEPS'
set -euo pipefail
cd "$(dirname "$0")"
STEPS
sed -E 's/(orogen help generate:terrace)$/\1 | tee -a help.txt/' "$work/steps.sh" >>"$work/run-steps.sh"
HOME="$work/home" CMAKE_BUILD_TYPE=Release bash "$work/run-steps.sh" >"$work/steps.log" 2>&1 ||
    { echo "FAIL: the README's plugin steps failed:"; tail -40 "$work/steps.log"; exit 1; }
helps=$(grep -c '^generate:terrace — cut a terrain into flat steps' "$work/help.txt" || true)
steps=$(grep -c 'orogen help generate:terrace' "$work/steps.sh")
[ "$helps" = "$steps" ] && [ "$steps" -ge 2 ] ||
    { echo "FAIL: $helps of $steps 'orogen help generate:terrace' steps described the plugin"; cat "$work/steps.log"; exit 1; }

# Both binaries the README uses load the plugin and run a spec with it.
cat >"$work/spec.orogen" <<'SPEC'
orogen 1
seed 1
grid 65 cell=10
base = generate:diamond-square(amplitude=100)
steps = generate:terrace(base, step=25)
export:png(steps, path="steps.png")
SPEC
for pair in "$build/bin/orogen:$work/terrace/build" "$work/home/.local/bin/orogen:$work/terrace/build-installed"; do
    orogen=${pair%%:*} plugin=${pair#*:}
    test -f "$plugin/terrace.so" || { echo "FAIL: the plugin was not built in $plugin"; exit 1; }
    # (captured first: grep -q would close the pipe early, and pipefail would blame orogen's SIGPIPE)
    version=$(OROGEN_PLUGIN_PATH="$plugin" "$orogen" version)
    grep -q "terrace .*1.0.0" <<<"$version" || { echo "FAIL: $orogen version does not show the plugin"; exit 1; }
    rm -rf "$work/out"
    OROGEN_PLUGIN_PATH="$plugin" "$orogen" run "$work/spec.orogen" --out "$work/out" --quiet
    test -s "$work/out/steps.png" || { echo "FAIL: no output from $orogen"; exit 1; }
done
echo "out-of-tree plugin: the README's steps built it against the build tree and an install; both load and run it"
