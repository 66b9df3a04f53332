"""orogen from Python: run pipeline specs and single nodes, and get their values back as numpy arrays.

    import orogen
    values = orogen.run("pipelines/default.orogen", seed=7, set={"scree.iterations": 80})
    terrain = values["scree"]           # orogen.Heightmap: .height, .layers, .cell
    terrain.height                      # float32 (rows, columns), row 0 the north edge
    worn = orogen.node("erode:thermal", terrain, talus=35, iterations=50)

See docs/python.md.
"""
import math as _math

try:  # every value comes back as a numpy array: without numpy nothing would work, so say so now
    import numpy as _numpy  # noqa: F401
except ImportError as _error:
    import sys as _sys

    raise ImportError(
        f"orogen needs numpy, which {_sys.executable} cannot import ({_error}); orogen's module was built for "
        "the interpreter `make` configured (Debian's /usr/bin/python3, with python3-numpy from tools/setup.sh): "
        "run /usr/bin/python3, or install numpy for this one (docs/python.md)") from None

from . import _orogen
from ._orogen import Heightmap, Series, help, nodes, run

__all__ = ["Heightmap", "Model", "Series", "help", "node", "nodes", "run"]

def _literal(value, where):
    """A Python value as the spec writes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not _math.isfinite(value):
            raise ValueError(f"{where} is {value}; give a finite number")
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(value, (tuple, list)):
        if len(value) > 0 and all(isinstance(v, (tuple, list)) for v in value):
            return "[" + ", ".join(_literal(tuple(v), where) for v in value) + "]"
        if len(value) == 2 and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            return f"({_literal(value[0], where)}, {_literal(value[1], where)})"
    raise ValueError(f"{where}: cannot give a parameter the Python value {value!r} (give a number, bool, string, "
                     "(x, y) point or a list of points)")


def _grid_of(array, i):
    """A numpy input checked (its samples are checked for NaN and infinity as they are copied in)."""
    import numpy as np

    if not isinstance(array, np.ndarray):
        raise ValueError(f"input {i} is a {type(array).__name__}; give an orogen.Heightmap or a 2-D numpy array")
    if array.ndim != 2:
        raise ValueError(f"input {i} has shape {array.shape}; a heightmap is a 2-D array (rows north to south)")
    if array.dtype != np.float32:
        raise ValueError(f"input {i} is {array.dtype}; orogen heightmaps are float32: pass a.astype(np.float32)")
    if array.shape[0] < 2 or array.shape[1] < 2:
        raise ValueError(f"input {i} is {array.shape[1]}x{array.shape[0]}; a heightmap needs at least 2 vertices a side")
    return array


def node(name, *inputs, cell=None, grid=None, spec_seed=0, label="result", threads=None, **params):
    """Run one node on numpy arrays or earlier values and return its result.

    `inputs` are orogen.Heightmap values (from run() or node()) or 2-D float32 numpy arrays (rows north to
    south; `cell` gives their spacing in metres, default 1). `params` are the node's parameters, checked as
    the spec checker checks them, with its messages (ValueError). A node without inputs (a generator) runs on
    a grid of `grid=(width, height)` vertices (default: the first input's size, else 513 x 513). The node's
    seed comes from `spec_seed` and `label`, as it would in a spec whose seed line is `spec_seed` and where
    the node is named `label`, so node() gives the same bits as that spec.

    The inputs are handed to the node in memory, by name: no file is written, not even a temporary one. An
    orogen.Heightmap crosses as it is, layers and all, without a copy (a node that changes its input works
    on a copy of it, as in a spec where another node reads that value too). A numpy array is copied once,
    into the node's heightmap (orogen's heightmaps own their memory and cannot borrow numpy's); any layout
    is read directly, C or Fortran order or a strided slice, so that copy is the only one; a node that
    changes its input then works on that copy in place.
    """
    if cell is not None and not (isinstance(cell, (int, float)) and _math.isfinite(cell) and cell > 0):
        raise ValueError(f"cell must be a number of metres above 0, got {cell!r}")
    if not isinstance(label, str) or not label.isidentifier():
        raise ValueError(f"label must be a name as a spec writes one (letters, digits, _), got {label!r}")
    lines = [f"orogen 1", f"seed {int(spec_seed)}"]
    notes, bound = [], []
    size = None
    for i, value in enumerate(inputs, start=1):
        if isinstance(value, Heightmap):
            rows, cols, spacing = value.shape[0], value.shape[1], value.cell
            what = "an orogen.Heightmap"
        else:
            array = _grid_of(value, i)
            rows, cols, spacing = array.shape[0], array.shape[1], (1.0 if cell is None else float(cell))
            value = array
            what = "a float32 array"
        if size is None:
            size = (cols, rows, spacing)
        bound.append((f"input{i}", value, spacing))
        # One line per input, where a spec would make it: the node's line, and the checker's line:col in a
        # message, stay where they were when inputs were imported from files.
        notes.append(f"# input{i}: {what}, {cols}x{rows}, cell {spacing!r} m, handed to the run in memory")
    if grid is not None:
        if not (isinstance(grid, (tuple, list)) and len(grid) == 2 and all(isinstance(v, int) for v in grid)):
            raise ValueError(f"grid must be (width, height) in vertices, got {grid!r}")
        size = (grid[0], grid[1], size[2] if size else (1.0 if cell is None else float(cell)))
    if size is None:
        size = (513, 513, 1.0 if cell is None else float(cell))
    lines.append(f"grid {int(size[0])}x{int(size[1])} cell={float(size[2])!r}")
    lines += notes
    args = [f"input{i}" for i in range(1, len(inputs) + 1)]
    args += [f"{k}={_literal(v, k)}" for k, v in params.items()]
    lines.append(f"{label} = {name}({', '.join(args)})")
    values = _orogen._run_node("\n".join(lines) + "\n", bound, threads=threads)
    return values.get(label)


class Model:
    """A landscape-evolution loop of processes, stepped from Python (the landlab habit, at C++ speed).

        model = orogen.Model(terrain, cell=30, open="ns", processes=[
            ("uplift", {"rate": 1}),
            ("flow", {}),
            ("creep", {"diffusivity": 0.5}),
            ("stream-power", {"erodibility": 2e-5, "m": 0.5}),
        ])
        for _ in range(10):
            model.step(1e4)                         # one step of dt years: every process, in order
            z = model["elevation"]                  # a float64 (rows, columns) copy
            model["elevation"] = np.minimum(z, 3000)  # write a field back between steps
        terrain = model.result()                    # an orogen.Heightmap with the processes' layers

    `terrain` is an orogen.Heightmap or a 2-D float32 array (rows north to south, `cell` metres apart).
    `processes` are an erode:evolve body's processes, in order, as (name, {parameter: value}) pairs: the
    kernel checks them as it checks a spec (unknown processes, parameters out of range, fields read before
    any process makes them: ValueError with the spec checker's message). `open`, `base_level`, `substeps`
    and `seed` are erode:evolve's and a spec's (the model's seed is that of a node named `label`), so a
    model stepped here gives the bits of the same body in a spec. docs/processes.md lists the processes.
    """

    def __init__(self, terrain, processes, *, cell=None, open="nesw", base_level="edge", substeps=1, seed=0,
                 label="model"):
        if not isinstance(terrain, Heightmap):
            terrain = _grid_of(terrain, 1)
        if not label.replace("_", "a").isalnum() or not label[0].isalpha():
            raise ValueError(f"label must be a name as a spec writes one (letters, digits, _), got {label!r}")
        body = []
        for k, item in enumerate(processes):
            if not (isinstance(item, (tuple, list)) and len(item) == 2 and isinstance(item[0], str)
                    and isinstance(item[1], dict)):
                raise ValueError(f"process {k + 1} is {item!r}; give (name, {{parameter: value}}) pairs")
            name, params = item
            args = ", ".join(f"{p}={_literal(v, name + '.' + p)}" for p, v in params.items())
            body.append(f"    {name}({args})")
        lines = ["orogen 1", f"seed {int(seed)}",
                 f"{label} = erode:evolve(terrain, years=1e9, dt=1, substeps={int(substeps)}, "
                 f"open={_literal(open, 'open')}, base_level={_literal(base_level, 'base_level')}) {{"]
        lines += body + ["}"]
        self._model = _orogen._Model("\n".join(lines) + "\n", label, terrain, 1.0 if cell is None else float(cell))

    def step(self, dt, steps=1):
        """Run `steps` steps of `dt` years."""
        self._model.step(float(dt), int(steps))

    def __getitem__(self, name):
        return self._model.field(name)

    def __setitem__(self, name, values):
        self._model.set_field(name, values)

    @property
    def fields(self):
        """The fields the processes share: elevation, uplifted and each process's."""
        return list(self._model.fields)

    @property
    def time(self):
        """Years simulated so far."""
        return self._model.time

    def result(self):
        """The terrain now, with the processes' layers (drainage, flow_direction, ...) and uplifted."""
        return self._model.result()
