#!/usr/bin/env bash
# tools/paraview.sh DIR — ParaView's pvbatch for the export:paraview-state test,
# unpacked into DIR (the build tree; never system-wide).
#
# Debian's python3-paraview cannot be installed beside libvtk9-dev (both ship
# the `vtkmodules` Python package), so the two .debs are fetched with
# `apt-get download` and unpacked with `dpkg -x`; DIR/pvbatch is a wrapper
# that puts them on PATH, LD_LIBRARY_PATH and PYTHONPATH. Everything else
# pvbatch needs at run time is installed by tools/setup.sh (checked here with ldd).
#
# Exit 0 and DIR/pvbatch when ParaView is ready. When the packages cannot be
# downloaded (no network, no Debian archive), exit 0 with the reason in
# DIR/unavailable: the test then skips and prints it. Anything else (a broken
# unpack, a library missing) is an error: exit 1.
set -euo pipefail

dir=${1:?usage: tools/paraview.sh DIR}
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
packages=(paraview python3-paraview)

rm -f "$dir/unavailable"
if [[ -x "$dir/pvbatch" && -f "$dir/.complete" ]]; then
  echo "paraview: ready in $dir"
  exit 0
fi
rm -f "$dir/.complete"

# 1. Download the .debs (the version apt knows: 5.11 on Debian 12).
mkdir -p "$dir/debs"
rm -f "$dir"/debs/*.deb
fetch() { (cd "$dir/debs" && apt-get download "${packages[@]}" >"$dir/debs/apt.log" 2>&1); }
if ! fetch; then
  # An image with empty package lists: refresh them when we may, then retry once.
  if [[ $(id -u) -eq 0 ]]; then
    apt-get update -qq >>"$dir/debs/apt.log" 2>&1 || true
  elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    sudo -n apt-get update -qq >>"$dir/debs/apt.log" 2>&1 || true
  fi
  if ! fetch; then
    {
      echo "cannot download ${packages[*]} with apt-get download (no network or no Debian archive?):"
      tail -n 5 "$dir/debs/apt.log"
    } >"$dir/unavailable"
    echo "paraview: $(head -n 1 "$dir/unavailable")" >&2
    exit 0
  fi
fi

# 2. Unpack beside each other.
rm -rf "$dir/root"
for deb in "$dir"/debs/*.deb; do dpkg -x "$deb" "$dir/root"; done
bin="$dir/root/usr/bin/pvbatch"
[[ -x "$bin" ]] || { echo "paraview: error: no usr/bin/pvbatch in the unpacked packages" >&2; exit 1; }
libdir=$(dirname "$(ls "$dir"/root/usr/lib/*/libvtkRemotingCore-pv*.so.1 | head -n 1)")
pvlibdir=$(ls -d "$libdir"/paraview-* | head -n 1)
pythondir="$dir/root/usr/lib/python3/dist-packages"
[[ -d "$pythondir/paraview" ]] || { echo "paraview: error: no paraview Python package in $pythondir" >&2; exit 1; }

# 3. What pvbatch links must be on this machine (tools/setup.sh installs it).
missing=$(LD_LIBRARY_PATH="$libdir:$pvlibdir" ldd "$bin" | awk '/not found/ {print $1}' | sort -u)
if [[ -n "$missing" ]]; then
  echo "paraview: error: pvbatch needs libraries that are not installed: $(echo $missing)" >&2
  echo "  run tools/setup.sh (it installs ParaView's run-time libraries), or apt-get install the packages that hold them" >&2
  exit 1
fi

# 4. The wrapper the tests (and people) run.
cat >"$dir/pvbatch" <<WRAPPER
#!/bin/sh
# pvbatch from Debian's paraview $(dpkg-deb -f "$(ls "$dir"/debs/paraview_*.deb)" Version), unpacked by tools/paraview.sh.
export PATH="$dir/root/usr/bin\${PATH:+:\$PATH}"
export LD_LIBRARY_PATH="$libdir:$pvlibdir\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
export PYTHONPATH="$pythondir\${PYTHONPATH:+:\$PYTHONPATH}"
exec "$bin" "\$@"
WRAPPER
chmod +x "$dir/pvbatch"
echo 'print("pvbatch ok")' >"$dir/probe.py"
if ! out=$("$dir/pvbatch" "$dir/probe.py" 2>&1) || [[ "$out" != *"pvbatch ok"* ]]; then
  echo "paraview: error: the unpacked pvbatch does not run:" >&2
  echo "$out" | tail -n 20 >&2
  exit 1
fi
rm -f "$dir"/debs/*.deb  # 73 MB the unpacked tree no longer needs
touch "$dir/.complete"
echo "paraview: ready in $dir"
