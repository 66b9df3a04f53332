# Run by pvbatch (tests/plugins/export/paraview/pvbatch_test.cpp):
#   pvbatch inspect_state.py STATE.py OUT_FOLDER
# Runs the shipped state script as a user would (`pvbatch STATE.py --screenshot
# OUT/state.png --size 640x400 --save-state OUT/view.pvsm`, at the time it opens at), then reports what
# ParaView built, as JSON in OUT/report.json, with pictures at the first and last time step
# (OUT/first.png, OUT/last.png).
import json
import os
import sys

state, out = sys.argv[1], sys.argv[2]
sys.argv = [state, "--screenshot", os.path.join(out, "state.png"), "--size", "640x400",
            "--save-state", os.path.join(out, "view.pvsm")]
run = {"__file__": state, "__name__": "__main__"}
with open(state) as f:
    exec(compile(f.read(), state, "exec"), run)

import numpy  # noqa: E402
from paraview import servermanager  # noqa: E402
from paraview.simple import *  # noqa: E402,F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402

view = GetActiveView()
scene = GetAnimationScene()
report = {"exaggeration": run["RUN"]["exaggeration"], "layer": run["RUN"]["layer"],
          "opened_at": scene.AnimationTime}
terrain = FindSource("terrain")
report["terrain_bounds"] = list(terrain.GetDataInformation().GetBounds())
report["terrain_points"] = terrain.GetDataInformation().GetNumberOfPoints()
display = GetDisplayProperties(terrain, view)
report["colour_array"] = [display.ColorArrayName[0], display.ColorArrayName[1]]
lut = GetColorTransferFunction(display.ColorArrayName[1])
report["categorical"] = int(lut.InterpretValuesAsCategories)
report["annotations"] = list(lut.Annotations)
report["rgb_points"] = list(lut.RGBPoints)
report["log_scale"] = int(lut.UseLogScale)
report["colour_space"] = str(lut.ColorSpace).strip("'")
report["scalar_bar"] = int(GetScalarBar(lut, view).Visibility)
report["scalar_bar_title"] = GetScalarBar(lut, view).Title
# The coloured array as ParaView reads it, and its 2nd and 98th percentiles (computed here, not by orogen).
values = vtk_to_numpy(servermanager.Fetch(terrain).GetPointData().GetArray(display.ColorArrayName[1]))
report["data_p2_p98"] = [float(numpy.percentile(values, 2)), float(numpy.percentile(values, 98))]
report["times"] = list(GetTimeKeeper().TimestepValues)
report["play_mode"] = str(scene.PlayMode).strip("'")
report["sources"] = sorted(name for (name, _id) in GetSources().keys())
report["camera_position"] = list(view.CameraPosition)
report["camera_focal_point"] = list(view.CameraFocalPoint)
report["camera_view_up"] = list(view.CameraViewUp)
shown = [n for n in ("plates (draped)", "collisions (draped)", "particles (stretched)", "sediment-laden particles")
         if FindSource(n)]


def points(name):
    source = FindSource(name)
    source.UpdatePipeline(scene.AnimationTime)
    return source.GetDataInformation().GetNumberOfPoints()


def z_range(name):
    source = FindSource(name)
    source.UpdatePipeline(scene.AnimationTime)
    b = source.GetDataInformation().GetBounds()
    return [b[4], b[5]]


def at(time, picture):
    scene.AnimationTime = time
    key = "first" if picture == "first.png" else "last"
    report["shown_at_" + key] = {n: points(n) for n in shown}
    if FindSource("plates (draped)"):
        report["plates_z_at_" + key] = z_range("plates (draped)")
    SaveScreenshot(os.path.join(out, picture), view, ImageResolution=[640, 400])


if report["times"]:
    at(report["times"][0], "first.png")
    at(report["times"][-1], "last.png")
with open(os.path.join(out, "report.json"), "w") as f:
    json.dump(report, f, indent=1)
