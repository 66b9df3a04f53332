# Run by pvbatch (tests/plugins/export/paraview/pvbatch_test.cpp):
#   pvbatch inspect_state.py STATE.py OUT_FOLDER
# Runs the shipped state script as a user would (`pvbatch STATE.py --screenshot
# OUT/first.png --size 640x400 --save-state OUT/view.pvsm`), then reports what ParaView built, as JSON in
# OUT/report.json, and a second picture at the last time step (OUT/last.png).
import json
import os
import sys

state, out = sys.argv[1], sys.argv[2]
sys.argv = [state, "--screenshot", os.path.join(out, "first.png"), "--size", "640x400",
            "--save-state", os.path.join(out, "view.pvsm")]
run = {"__file__": state, "__name__": "__main__"}
with open(state) as f:
    exec(compile(f.read(), state, "exec"), run)

from paraview.simple import *  # noqa: E402,F401,F403

view = GetActiveView()
report = {"exaggeration": run["RUN"]["exaggeration"], "layer": run["RUN"]["layer"]}
terrain = FindSource("terrain")
report["terrain_bounds"] = list(terrain.GetDataInformation().GetBounds())
report["terrain_points"] = terrain.GetDataInformation().GetNumberOfPoints()
display = GetDisplayProperties(terrain, view)
report["colour_array"] = [display.ColorArrayName[0], display.ColorArrayName[1]]
lut = GetColorTransferFunction(display.ColorArrayName[1])
report["categorical"] = int(lut.InterpretValuesAsCategories)
report["annotations"] = list(lut.Annotations)
report["rgb_points"] = list(lut.RGBPoints)
report["colour_space"] = str(lut.ColorSpace).strip("'")
report["scalar_bar"] = int(GetScalarBar(lut, view).Visibility)
report["scalar_bar_title"] = GetScalarBar(lut, view).Title
report["times"] = list(GetTimeKeeper().TimestepValues)
report["play_mode"] = str(GetAnimationScene().PlayMode).strip("'")
report["sources"] = sorted(name for (name, _id) in GetSources().keys())
report["camera_position"] = list(view.CameraPosition)
report["camera_focal_point"] = list(view.CameraFocalPoint)
report["camera_view_up"] = list(view.CameraViewUp)


def points(name):
    source = FindSource(name)
    source.UpdatePipeline(GetAnimationScene().AnimationTime)
    return source.GetDataInformation().GetNumberOfPoints()


report["shown_at_first"] = {n: points(n) for n in ("plates (raised)", "collisions (raised)", "particles (stretched)")
                            if FindSource(n)}
if report["times"]:
    GetAnimationScene().AnimationTime = report["times"][-1]
    report["shown_at_last"] = {n: points(n) for n in report["shown_at_first"]}
    SaveScreenshot(os.path.join(out, "last.png"), view, ImageResolution=[640, 400])
with open(os.path.join(out, "report.json"), "w") as f:
    json.dump(report, f, indent=1)
