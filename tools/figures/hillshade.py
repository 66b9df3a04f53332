#!/usr/bin/python3
"""Hillshades side by side, for the docs: light from the north-west, 45° up.

    tools/figures/hillshade.py OUT.png [--size N] [--cell M] FILE[=TITLE] ...

FILE is a square float32 .r32 (orogen's RAW, metres) or any raster GDAL opens
(python3-gdal). The first N × N samples (default 600) of each are shaded with
central differences at M metres a cell (default 30). Drawn with matplotlib
(python3-matplotlib: a tool for the docs, so tools/setup.sh leaves it out).
"""
import argparse

import numpy as np


def load(path):
    if path.endswith(".r32"):
        z = np.fromfile(path, dtype=np.float32)
        side = int(round(np.sqrt(z.size)))
        if side * side != z.size:
            raise SystemExit(f"{path}: {z.size} samples is not a square grid")
        return z.reshape(side, side).astype(np.float64)
    from osgeo import gdal

    data = gdal.Open(path)
    if data is None:
        raise SystemExit(f"{path}: GDAL cannot open it")
    return data.ReadAsArray().astype(np.float64)


def shade(z, cell):
    gy, gx = np.gradient(z, cell)
    azimuth, altitude = np.radians(315.0), np.radians(45.0)
    slope = np.arctan(np.hypot(gx, gy))
    aspect = np.arctan2(-gx, gy)
    return np.sin(altitude) * np.cos(slope) + np.cos(altitude) * np.sin(slope) * np.cos(azimuth - aspect)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out")
    p.add_argument("files", nargs="+")
    p.add_argument("--size", type=int, default=600)
    p.add_argument("--cell", type=float, default=30.0)
    a = p.parse_args()
    try:
        import matplotlib
    except ImportError:
        raise SystemExit("hillshade.py draws with matplotlib: apt-get install python3-matplotlib")

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(a.files), figsize=(5 * len(a.files), 5.3))
    for ax, spec in zip(np.atleast_1d(axes), a.files):
        path, _, title = spec.partition("=")
        z = load(path)[: a.size, : a.size]
        ax.imshow(shade(z, a.cell), cmap="gray", vmin=0.0, vmax=1.0)
        ax.set_title(title or path.split("/")[-1])
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(a.out, dpi=72)


if __name__ == "__main__":
    main()
