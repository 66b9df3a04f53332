#!/usr/bin/python3
"""Texture figures that `orogen analyze` does not report (docs/realism.md).

    tools/figures/texture_figures.py FILE [FILE ...]

FILE is a square float32 .r32 (orogen's RAW, metres, 30 m cells unless --cell)
or any raster GDAL opens (python3-gdal; a geographic one is converted at its mid
latitude). For each it prints, over the samples steeper than 6° (hillslopes and
channels, not flats):

- planar %: the share whose Laplacian curvature lies within a fifth of a
  standard deviation of zero (smooth planes; integer DEMs such as the Rif's
  quantise it);
- slope change: the median change of slope (°) from one sample to the next
  east-west (the slope by central differences);
- curvature skewness: the skewness of the Laplacian curvature (5-point
  stencil); positive when sharp concave valley bottoms outweigh sharp convex
  crests;
- channel curvature: the mean Laplacian curvature (1/km) of the samples whose
  D8 drainage area exceeds 1 km² (a V notch at 30 m: 30-40 /km; a valley with a
  floor or a rounded bottom: less);
- valley width: across the same channel samples (along the axis, x or y, on
  which the central difference is the smaller: across the river, for one that
  runs along the other axis), the median height of the two samples d cells to
  either side above the river, for d = 1 … 4; the width (m) at which that
  median section stands 10 m above the river, interpolated linearly (walls at
  30° from the river itself: 35 m; a valley floor widens it).

The first three are measured here rather than in `orogen analyze` because they
are still being judged: the first depends on the DEM's vertical resolution, the
second counts the DEM's own noise. The last two are `orogen analyze` figures
since `4c3b145`, 2026-12-06 (`channel_curvature`, `valley_width`), measured there on the
whole network: the D8 here runs on the unfilled heights, so every pit stops the
drainage area and they see only the channels above the first pit (about half,
none draining more than ~10 km²). They stay here to compare with earlier notes.
"""
import argparse
import os
import sys

import numpy as np


def fail(message):
    """Bad input: say what is wrong on stderr, exit 2 (nothing was measured)."""
    print(f"texture_figures: {message}", file=sys.stderr)
    sys.exit(2)


def load(path, cell):
    if not os.path.isfile(path):
        fail(f"{path}: no such file (give a .r32 terrain or a raster GDAL opens)")
    if path.endswith(".r32"):
        z = np.fromfile(path, dtype=np.float32)
        side = int(round(np.sqrt(z.size)))
        if side * side != z.size:
            fail(f"{path}: {z.size} samples is not a square grid")
        return z.reshape(side, side).astype(np.float64), cell
    from osgeo import gdal

    data = gdal.Open(path)
    if data is None:
        fail(f"{path}: GDAL cannot open it")
    band = data.GetRasterBand(1)
    z = band.ReadAsArray().astype(np.float64)
    if band.GetNoDataValue() is not None:
        z[z == band.GetNoDataValue()] = np.nan
    gt = data.GetGeoTransform()
    size = abs(gt[1])
    if size < 0.01:  # degrees: metres at the mid latitude
        size *= 111320.0 * np.cos(np.radians(gt[3] + gt[5] * z.shape[0] / 2))
    return z, size


def d8_area(z, cell):
    """Drainage area (m²) by D8: each sample drains to its steepest lower neighbour."""
    rows, cols = z.shape
    h = np.where(np.isfinite(z), z, -np.inf)
    index = np.arange(z.size).reshape(z.shape)
    best = np.zeros(z.shape)
    receiver = np.full(z.shape, -1, dtype=np.int64)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            if di == 0 and dj == 0:
                continue
            nb = np.full(z.shape, np.inf)
            nid = np.full(z.shape, -1, dtype=np.int64)
            dst = (slice(max(-di, 0), rows + min(-di, 0)), slice(max(-dj, 0), cols + min(-dj, 0)))
            src = (slice(max(di, 0), rows + min(di, 0)), slice(max(dj, 0), cols + min(dj, 0)))
            nb[dst] = h[src]
            nid[dst] = index[src]
            drop = (h - nb) / (cell * np.hypot(di, dj))
            better = np.isfinite(drop) & (drop > best)
            best = np.where(better, drop, best)
            receiver = np.where(better, nid, receiver)
    area = np.full(z.size, cell * cell)
    rcv = receiver.ravel()
    for i in np.argsort(-h, axis=None, kind="stable"):  # donors before receivers
        if rcv[i] >= 0:
            area[rcv[i]] += area[i]
    return area.reshape(z.shape)


def figures(path, z, cell):
    if min(z.shape) < 3:
        fail(f"{path}: {z.shape[1]} x {z.shape[0]} samples; the curvature needs at least 3 x 3")
    gy, gx = np.gradient(z, cell)
    slope = np.degrees(np.arctan(np.hypot(gx, gy)))
    lap = (z[:-2, 1:-1] + z[2:, 1:-1] + z[1:-1, :-2] + z[1:-1, 2:] - 4 * z[1:-1, 1:-1]) / cell**2
    inner = slope[1:-1, 1:-1]
    steep = (inner > 6.0) & np.isfinite(lap)
    if not steep.any():
        fail(f"{path}: no sample is steeper than 6°, so there is no hillslope to measure")
    c = lap[steep]
    spread = c.std()
    # A surface of one curvature (a plane, a cylinder) has no spread: all of it planar if that is 0.
    planar = np.mean(np.abs(c) < 0.2 * spread) if spread > 0 else float(np.all(np.abs(c) < 1e-12))
    skew = np.mean((c - c.mean()) ** 3) / spread**3 if spread > 0 else 0.0
    change = np.abs(np.diff(slope, axis=1))
    counted = (slope[:, :-1] > 6.0) & np.isfinite(change)
    area = d8_area(z, cell)[1:-1, 1:-1]
    channel = steep & (area > 1e6)
    return {
        "planar %": 100.0 * planar,
        "slope change °": float(np.median(change[counted])),
        "curvature skewness": float(skew),
        "channel curvature /km": float(np.mean(lap[channel]) * 1000.0) if channel.any() else float("nan"),
        "valley width m": valley_width(z, cell, channel),
    }


def valley_width(z, cell, channel, rise=10.0, reach=4):
    """Width (m) at which the median cross-section of the channel samples stands `rise` m above the river."""
    rows, cols = z.shape
    ys, xs = np.nonzero(channel)
    ys, xs = ys + 1, xs + 1  # `channel` covers the inner samples
    keep = (ys >= reach) & (xs >= reach) & (ys < rows - reach) & (xs < cols - reach)
    ys, xs = ys[keep], xs[keep]
    if ys.size == 0:
        return float("nan")
    across_x = np.abs(z[ys, xs + 1] - z[ys, xs - 1]) <= np.abs(z[ys + 1, xs] - z[ys - 1, xs])
    section = [0.0]
    for d in range(1, reach + 1):
        side = np.where(across_x, (z[ys, xs - d] + z[ys, xs + d]) / 2.0, (z[ys - d, xs] + z[ys + d, xs]) / 2.0)
        section.append(float(np.nanmedian(side - z[ys, xs])))
    for d in range(1, reach + 1):
        if section[d] >= rise:
            below, above = section[d - 1], section[d]
            return 2.0 * cell * (d - 1 + (rise - below) / (above - below))
    return float("nan")  # wider than the reach: the section stays below `rise`


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("files", nargs="+")
    p.add_argument("--cell", type=float, default=30.0, help="cell size of .r32 files (m)")
    a = p.parse_args()
    if a.cell <= 0:
        fail(f"--cell {a.cell}: give the cell size in metres, above 0")
    rows = [(path, figures(path, *load(path, a.cell))) for path in a.files]
    names = list(rows[0][1])
    width = max(len(path) for path, _ in rows)
    print("file".ljust(width), *(n.rjust(22) for n in names))
    for path, f in rows:
        print(path.ljust(width), *(f"{f[n]:22.2f}" for n in names))


if __name__ == "__main__":
    main()
