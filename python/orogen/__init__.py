"""orogen from Python: run pipeline specs and get their values back as numpy arrays.

    import orogen
    values = orogen.run("pipelines/default.orogen", seed=7, set={"base.amplitude": 600})
    terrain = values["worn"]            # orogen.Heightmap: .height, .layers, .cell
    terrain.height                      # float32 (rows, columns), row 0 the north edge

See docs/python.md.
"""
from ._orogen import Heightmap, Series, help, nodes, run

__all__ = ["Heightmap", "Series", "help", "nodes", "run"]
