#!/usr/bin/env bash
# Installs what orogen needs on Debian 12, only what is missing. Idempotent;
# works as root or through sudo. Called by `make demo` / `make test`.
#   tools/setup.sh          the Debian packages
#   tools/setup.sh --tests  and what only the tests use (the Khronos glTF validator, from npm)
set -euo pipefail
for_tests=0
[[ "${1:-}" == "--tests" ]] && for_tests=1

packages=(
  cmake ninja-build g++ pkg-config
  libglm-dev libbox2d-dev libosmesa6-dev libvtk9-dev libopenvdb-dev libtinygltf-dev nlohmann-json3-dev
  libboost-dev libboost-filesystem-dev libboost-iostreams-dev libboost-system-dev
  libgdal-dev gdal-bin
  libxgboost-dev                                # orogen analyze --discriminate (XGBoost C API)
  libopenexr-dev openexr
  python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib   # matplotlib: docs/python.md's plots
  libssl-dev libxxhash-dev libstb-dev libpng-dev libdeflate-dev libtbb-dev libgtest-dev libgmock-dev libbenchmark-dev
  libavcodec-dev libavformat-dev libswscale-dev ffmpeg
  xvfb xauth libx11-dev
  clang-14 libclang-rt-14-dev clang-format-14   # clang-format-14: the Format test checks .clang-format
  clang-tidy-14               # make tidy (CI): functions within 150 lines and 8 parameters
  openmpi-bin libopenmpi-dev
  gnuplot-nox                 # analyze:terrain's charts (pngcairo)
)

# ParaView's pvbatch (the export:paraview-state test) is not installed here:
# Debian's python3-paraview conflicts with libvtk9-dev's VTK Python package,
# so tools/paraview.sh (the ctest fixture paraview_fetch) unpacks the two
# .debs into build/paraview. Everything pvbatch links is already pulled in by
# the packages above (checked with ldd against their dependency closure).

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} Debian package(s): ${missing[*]}"
  if [[ $(id -u) -eq 0 ]]; then
    as_root=()
  elif command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    echo "setup: error: these packages are missing and I am neither root nor able to sudo:" >&2
    echo "  apt-get install ${missing[*]}" >&2
    exit 2
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${as_root[@]}" apt-get update -qq
  "${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The Khronos glTF validator (npm package gltf-validator) for the glTF export
# tests (`make test` only); skipped, with a note, where Node.js is not installed.
here=$(cd "$(dirname "$0")" && pwd)
if [[ $for_tests == 1 && -f "$here/package.json" ]]; then
  if command -v npm >/dev/null 2>&1; then
    if [[ ! -d "$here/node_modules/gltf-validator" ]]; then
      echo "setup: installing the glTF validator from the npm registry"
      npm install --prefix "$here" --no-audit --no-fund --loglevel=error >/dev/null || \
        echo "setup: warning: npm install failed; the glTF validator test will be skipped" >&2
    fi
  else
    echo "setup: note: Node.js/npm not found; the glTF validator test will be skipped"
  fi
fi
