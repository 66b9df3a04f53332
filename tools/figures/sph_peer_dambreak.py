#!/usr/bin/env python3
"""Martin & Moyce's dam break in SPlisHSPlasH, on the scene sph_validation runs (docs/erosion.md).

  sph_peer_dambreak.py scene PEERS/SPH/data/Scenes/db100k_dfsph.json OUT.json [across=40] [deep=32] [a=0.05715]
      the peer's own dam-break configuration (method, solver settings, boundary handling) with our geometry:
      a column a wide and 2a high against the back wall of a tank 5a long, `deep` particles wide (walls at
      both sides), particle radius a/(2·across), particle export (VTK) every ΔT = 0.05.
  sph_peer_dambreak.py front OUTPUT_DIR/vtk a [fps=1/(0.05·√(a/2g)): T every 0.05] [deep_m=W]
      from the exported frames, T = t·√(2g/a) and the front Z = x/a as sph_validation measures it (the
      leading particle's edge per slice one spacing wide across the tank, the median over the slices).
"""
import glob
import json
import math
import os
import re
import struct
import sys

G = 9.81


def args(rest):
    out = {}
    for a in rest:
        k, _, v = a.partition('=')
        out[k] = v
    return out


def scene(src, dst, rest):
    o = args(rest)
    across, deep, a = int(o.get('across', 40)), int(o.get('deep', 32)), float(o.get('a', 0.05715))
    s = a / across
    W = deep * s
    j = json.load(open(src))
    c = j['Configuration']
    # The time step's cap scaled with the particles (the peer's 0.005 s is for its 1 m dam break: at
    # millimetre particles its first steps blow the column apart).
    cap = c.get('cflMaxTimeStepSize', 0.005) * (s / 2) / 0.025
    c.update(particleRadius=s / 2, stopAt=3.05 * math.sqrt(a / (2 * G)), enableVTKExport=True,
             timeStepSize=cap, cflMaxTimeStepSize=cap,
             dataExportFPS=1.0 / (0.05 * math.sqrt(a / (2 * G))), particleAttributes='velocity')
    L, H = 5 * a, 3 * a
    rb = j['RigidBodies'][0]
    rb.update(translation=[L / 2, H / 2, W / 2], scale=[L, H, W],
              mapResolution=[round(L / (2 * s)), round(H / (2 * s)), round(W / (2 * s))])  # cells of the support radius
    # The peer fills a block with particles from one spacing inside its start and keeps them a spacing from
    # its walls (at half a spacing, as ours sit, its volume-map boundary blew the column apart in the first
    # steps): across × 2·across particles at x, y = s, 2s, ... (the column a wide and 2a high, half a spacing
    # further from the back wall and the floor than ours), deep − 1 across the tank.
    j['FluidBlocks'] = [{"denseMode": 0, "start": [0.0, 0.0, 0.0], "end": [a + s, 2 * a + s, W],
                         "translation": [0, 0, 0], "scale": [1, 1, 1]}]
    json.dump(j, open(dst, 'w'), indent=1)
    print(f'{dst}: column {a} x {2 * a} x {W:.5f} m in a tank {L} x {H} x {W:.5f} m, radius {s / 2:.6f} m, '
          f'export every {1 / c["dataExportFPS"]:.6f} s')


def read_points(path):
    data = open(path, 'rb').read()
    m = re.search(rb'POINTS (\d+) (float|double)\n', data)
    n, kind = int(m.group(1)), m.group(2)
    size, fmt = (4, 'f') if kind == b'float' else (8, 'd')
    start = m.end()
    vals = struct.unpack('>' + fmt * (3 * n), data[start:start + 3 * n * size])
    return [(vals[3 * i], vals[3 * i + 1], vals[3 * i + 2]) for i in range(n)]


def front(folder, a, rest):
    o = args(rest)
    fps = float(o.get("fps", 1.0 / (0.05 * math.sqrt(a / (2 * G)))))
    files = glob.glob(os.path.join(folder, 'ParticleData_Fluid_*.vtk'))
    frames = sorted((int(re.search(r'_(\d+)\.vtk$', f).group(1)), f) for f in files)
    print(f'# SPlisHSPlasH: T = t*sqrt(2g/a), Z = x/a ({len(frames)} frames from {folder})')
    for k, f in frames:
        pts = read_points(f)
        xs = [p[0] for p in pts]
        zs = [p[2] for p in pts]
        zmin, zmax = min(zs), max(zs)
        # the spacing from the particle count: the column is a x 2a x W of spacing s
        s = float(o['s']) if 's' in o else (a * 2 * a * (zmax - zmin + 1e-9)) ** (1 / 3) / len(pts) ** (1 / 3)
        slices = max(1, int(round((zmax - zmin) / s)) + 1)
        lead = [-1e30] * slices
        for x, z in zip(xs, zs):
            i = min(slices - 1, max(0, int((z - zmin) / s + 0.5)))
            lead[i] = max(lead[i], x + s / 2)
        lead = sorted(v for v in lead if v > -1e30)
        med = lead[len(lead) // 2] if len(lead) % 2 else 0.5 * (lead[len(lead) // 2 - 1] + lead[len(lead) // 2])
        t = (k - 1) / fps if k > 0 else 0.0
        print(f'{t * math.sqrt(2 * G / a):.4f} {med / a:.4f}')


if __name__ == '__main__':
    if len(sys.argv) >= 4 and sys.argv[1] == 'scene':
        scene(sys.argv[2], sys.argv[3], sys.argv[4:])
    elif len(sys.argv) >= 4 and sys.argv[1] == 'front':
        front(sys.argv[2], float(sys.argv[3]), sys.argv[4:])
    else:
        print(__doc__)
        sys.exit(2)
