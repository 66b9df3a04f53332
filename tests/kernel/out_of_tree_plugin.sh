#!/usr/bin/env bash
# Installs orogen into a scratch prefix, builds tests/external_plugin against
# it as a separate project would (find_package(orogen)), loads the result
# through OROGEN_PLUGIN_PATH with the installed binary, and runs a spec with it.
set -euo pipefail
build=$1 source=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
cmake -S "$source" -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$work/prefix" >"$work/configure.log"
cmake --build "$work/build" >"$work/build.log"
test -f "$work/build/terrace.so" || { echo "FAIL: the plugin was not built"; exit 1; }

orogen="$work/prefix/bin/orogen"
OROGEN_PLUGIN_PATH="$work/build" "$orogen" list generate | grep -q "^generate:terrace " ||
  { echo "FAIL: the installed orogen does not list generate:terrace"; exit 1; }
OROGEN_PLUGIN_PATH="$work/build" "$orogen" version | grep -q "terrace .*1.0.0" ||
  { echo "FAIL: orogen version does not show the plugin"; exit 1; }

cat >"$work/spec.orogen" <<'SPEC'
orogen 1
seed 1
grid 65 cell=10
base = generate:diamond-square(amplitude=100)
steps = generate:terrace(base, step=25)
export:png(steps, path="steps.png")
SPEC
OROGEN_PLUGIN_PATH="$work/build" "$orogen" run "$work/spec.orogen" --out "$work/out" --quiet
test -s "$work/out/steps.png" || { echo "FAIL: no output"; exit 1; }
echo "out-of-tree plugin: built, loaded and run"
