#!/usr/bin/env bash
# docs/plugins.md, step for step: its snow.cpp, CMakeLists.txt and snow_test.orogen as the page shows them,
# then its commands as written, in a scratch folder where `build` is this build tree: the plugin built
# against the build tree, `orogen help` describing it, its own ctest passing. Then the page's claims: the
# node runs through OROGEN_PLUGIN_PATH and adds its layer; without `.adds_layers` the spec is refused with
# the error the page quotes; the check hook's and the range's errors; every tree path the page names exists.
set -euo pipefail
build=$1 source=$2 doc=$3 work=$4
rm -rf "$work"
mkdir -p "$work/snow" "$work/undeclared"

# The first of the page's fenced blocks with a line matching $1.
block() {
    awk -v want="$1" '
        /^```/ { if (inside) { if (hit) { printf "%s", text; exit } inside = 0; next } inside = 1; hit = 0; text = ""; next }
        inside { text = text $0 "\n"; if ($0 ~ want) hit = 1 }' "$doc"
}
block '^// snow.cpp' >"$work/snow/snow.cpp"
block '^# CMakeLists.txt' >"$work/snow/CMakeLists.txt"
block '^# snow_test.orogen' >"$work/snow/snow_test.orogen"
block 'cmake -S snow' >"$work/steps.sh"
for f in snow.cpp CMakeLists.txt snow_test.orogen; do
    test -s "$work/snow/$f" || { echo "FAIL: the page shows no $f"; exit 1; }
done
grep -q 'orogen_DIR' "$work/steps.sh" || { echo "FAIL: the page does not build against the build tree"; exit 1; }
grep -q '^ctest ' "$work/steps.sh" || { echo "FAIL: the page does not run the plugin's tests"; exit 1; }

# The steps as the page writes them, from a folder holding `build` and `snow`.
ln -s "$(cd "$build" && pwd)" "$work/build"
{ echo 'set -euo pipefail'; echo 'cd "$(dirname "$0")"'; sed -E 's/(orogen help generate:snow)$/\1 | tee help.txt/' "$work/steps.sh"; } \
    >"$work/run-steps.sh"
CMAKE_BUILD_TYPE=Release bash "$work/run-steps.sh" >"$work/steps.log" 2>&1 ||
    { echo "FAIL: the page's steps failed:"; tail -40 "$work/steps.log"; exit 1; }
grep -q '^generate:snow — ' "$work/help.txt" || { echo "FAIL: 'orogen help generate:snow' did not describe the node"; cat "$work/steps.log"; exit 1; }
grep -q '^adds layers: snow$' "$work/help.txt" || { echo "FAIL: 'orogen help' does not list the layer"; cat "$work/help.txt"; exit 1; }
grep -q '100% tests passed, 0 tests failed out of 2' "$work/steps.log" ||
    { echo "FAIL: the plugin's own two tests did not both pass:"; cat "$work/steps.log"; exit 1; }

# The node through OROGEN_PLUGIN_PATH, its layer in the output, and the line the page quotes.
orogen=$build/bin/orogen
plugin=$work/snow/build
{ cat "$work/snow/snow_test.orogen"; echo 'export:vtk(snowy, path="snowy.vti")'; } >"$work/spec.orogen"
OROGEN_PLUGIN_PATH="$plugin" "$orogen" run "$work/spec.orogen" --out "$work/out" >"$work/run.log" 2>&1 ||
    { echo "FAIL: the spec did not run:"; cat "$work/run.log"; exit 1; }
grep -q 'snowy: snow on 48 % of the map' "$work/run.log" || { echo "FAIL: not the page's 48 %:"; cat "$work/run.log"; exit 1; }
grep -q 'snow on 48 % of the map' "$doc" || { echo "FAIL: the page no longer quotes the 48 %"; exit 1; }
test -s "$work/out/snow.png" || { echo "FAIL: no snow.png"; exit 1; }
grep -aq 'Name="snow"' "$work/out/snowy.vti" || { echo "FAIL: no snow layer in snowy.vti"; exit 1; }

# Errors, as the page shows them. check SPEC [--set ...] → the output, and the exit code 2.
refused() {
    local out code
    set +e
    out=$(OROGEN_PLUGIN_PATH="$1" "$orogen" check "$work/snow/snow_test.orogen" "${@:2}" 2>&1)
    code=$?
    set -e
    [ "$code" = 2 ] || { echo "FAIL: check ${*:2} was not refused (exit $code): $out" >&2; exit 1; }
    printf '%s\n' "$out"
}
# (outputs captured first: grep -q or head would close a pipe early, and pipefail would blame the writer)
out=$(refused "$plugin" --set snowy.high=500)
msg=${out%%$'\n'*}
grep -qF -- "$msg" "$doc" || { echo "FAIL: the page does not quote the check hook's error: $msg"; exit 1; }
out=$(refused "$plugin" --set snowy.max_angle=95)
grep -qF "'max_angle' of generate:snow is 95, out of range (0, 90]" <<<"$out" ||
    { echo "FAIL: max_angle=95 was not refused with its range"; exit 1; }

# Without .adds_layers: the layer is refused at check time, with the message the page quotes.
[ "$(grep -c '\.adds_layers = {"snow"}' "$work/snow/snow.cpp")" = 1 ] || { echo "FAIL: snow.cpp has no .adds_layers line"; exit 1; }
grep -v '\.adds_layers = {"snow"}' "$work/snow/snow.cpp" >"$work/undeclared/snow.cpp"
cp "$work/snow/CMakeLists.txt" "$work/undeclared/"
(cmake -S "$work/undeclared" -B "$work/undeclared/build" -Dorogen_DIR="$work/build" -DCMAKE_BUILD_TYPE=Release &&
    cmake --build "$work/undeclared/build") >"$work/undeclared.log" 2>&1 ||
    { echo "FAIL: the plugin without .adds_layers did not build:"; tail -20 "$work/undeclared.log"; exit 1; }
out=$(refused "$work/undeclared/build")
msg=$(grep 'error: export:png: no layer' <<<"$out" || true)
grep -q "no layer 'snow' on the input" <<<"$msg" || { echo "FAIL: an undeclared layer was not refused: $msg"; exit 1; }
# (the page's quote and the message, one the start of the other: the kernel may add a hint at the end)
actual="snow_test.orogen:${msg#*snow_test.orogen:}"
quoted=$(grep -m1 '^snow_test.orogen:[0-9]*:[0-9]*: error: export:png: no layer' "$doc" || true)
[ -n "$quoted" ] && { [[ $actual == "$quoted"* ]] || [[ $quoted == "$actual"* ]]; } ||
    { echo "FAIL: the page does not quote the refusal: $actual"; echo "it quotes: $quoted"; exit 1; }

# Every path of the tree the page names exists.
for p in $(grep -oE '`(plugins|kernel|tests|cmake|libs)/[^` ]+`' "$doc" | tr -d '`' | sort -u); do
    case $p in *'<'*) continue ;; esac
    test -e "$source/$p" || { echo "FAIL: the page names $p, which does not exist"; exit 1; }
done
echo "plugin guide: docs/plugins.md's plugin built against the build tree, its tests passed, its claims hold"
