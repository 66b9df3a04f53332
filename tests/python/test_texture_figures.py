"""tools/figures/texture_figures.py on surfaces whose answers are known, and on bad input."""
import os
import pathlib
import subprocess
import sys

import numpy as np

TOOL = pathlib.Path(os.environ["OROGEN_SOURCE_DIR"]) / "tools" / "figures" / "texture_figures.py"
CELL = 30.0


def measure(tmp_path, z):
    path = tmp_path / "t.r32"
    z.astype("<f4").tofile(path)
    run = subprocess.run([sys.executable, str(TOOL), str(path)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return [float(v) for v in run.stdout.splitlines()[1].split()[1:]]


def grid(n=201):
    y, x = np.mgrid[0:n, 0:n] * CELL
    return x, y


def test_a_plane_has_no_slope_change_and_no_channel(tmp_path):
    x, y = grid()
    planar, change, skew, channel, width = measure(tmp_path, np.tan(np.radians(20.0)) * y)
    assert change < 1e-3
    assert np.isnan(channel)  # every cell drains straight down the plane: none gathers 1 km²
    assert np.isnan(width)  # and so has no valley to measure


def test_a_v_valley_has_a_notchs_curvature_in_its_channel(tmp_path):
    # Two 30° walls meeting along x = mid, the floor falling 8° towards y = 0 (6 km, 36 km²):
    # the channel's Laplacian is the walls' kink, 2·tan 30°/cell, 38.5 /km, and the only
    # curvature: its concave tail makes the skewness large and positive.
    x, y = grid()
    mid = x[0, 100]
    z = np.abs(x - mid) * np.tan(np.radians(30.0)) + y * np.tan(np.radians(8.0))
    planar, change, skew, channel, width = measure(tmp_path, z)
    assert abs(channel - 2000.0 * np.tan(np.radians(30.0)) / CELL) < 0.5
    assert skew > 5.0
    assert planar > 95.0  # every wall cell is flat in curvature


def test_a_v_valley_is_as_wide_as_its_walls_make_it_10_m_up(tmp_path):
    # Walls at angle a rise 30 m·tan a a cell from the river: 10 m up, the valley is 2·10 m / tan a wide
    # (34.6 m at 30°, 74.6 m at 15°); the section is linear, so the interpolation is exact. The floor
    # falls 8° along y, across the axis the width is measured on.
    x, y = grid()
    mid = x[0, 100]
    for angle in (30.0, 15.0):
        z = np.abs(x - mid) * np.tan(np.radians(angle)) + y * np.tan(np.radians(8.0))
        width = measure(tmp_path, z)[4]
        assert abs(width - 20.0 / np.tan(np.radians(angle))) < 0.01, angle
    # The same valley along x: the width is measured across it, on the other axis.
    z = np.abs(y - mid) * np.tan(np.radians(30.0)) + x * np.tan(np.radians(8.0))
    assert abs(measure(tmp_path, z)[4] - 20.0 / np.tan(np.radians(30.0))) < 0.01


def test_bad_input_says_what_is_wrong_and_exits_2(tmp_path):
    missing = subprocess.run([sys.executable, str(TOOL), str(tmp_path / "none.r32")], capture_output=True, text=True)
    assert missing.returncode == 2 and "no such file" in missing.stderr
    flat = tmp_path / "flat.r32"
    np.zeros((20, 20), "<f4").tofile(flat)
    run = subprocess.run([sys.executable, str(TOOL), str(flat)], capture_output=True, text=True)
    assert run.returncode == 2 and "steeper than 6°" in run.stderr
    ragged = tmp_path / "ragged.r32"
    np.zeros(10, "<f4").tofile(ragged)
    run = subprocess.run([sys.executable, str(TOOL), str(ragged)], capture_output=True, text=True)
    assert run.returncode == 2 and "not a square grid" in run.stderr
