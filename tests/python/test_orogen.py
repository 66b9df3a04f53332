"""The Python module against the `orogen` binary: the same bytes, the same messages, the same refusals.

Run by ctest (python_module) with PYTHONPATH=<build>/python and OROGEN_CLI=<build>/bin/orogen.
"""
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np
import pytest

import orogen

CLI = os.environ["OROGEN_CLI"]

SPEC = """orogen 1
seed 5
grid 65 cell=20
b = generate:fault(iterations=40, displacement=8)
w = erode:hydraulic(b, iterations=5)
t = erode:thermal(w, iterations=20, timelapse_every=10)
export:raw(t, path="t.r32")
export:raw(w, path="w.r32")
"""


def cli(args, cwd):
    env = dict(os.environ, OROGEN_NO_CACHE="1", OROGEN_PLUGIN_PATH="")
    return subprocess.run([CLI] + args, cwd=cwd, env=env, capture_output=True, text=True)


def bits(a):
    return np.ascontiguousarray(a).view(np.uint32)


def test_run_gives_the_cli_bytes_and_every_named_value(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.orogen").write_text(SPEC)
    r = cli(["run", "s.orogen", "--out", "cli", "--quiet"], tmp_path)
    assert r.returncode == 0, r.stderr
    values = orogen.run(pathlib.Path("s.orogen"), out=pathlib.Path("py"))  # paths as str or pathlib.Path
    assert sorted(values) == ["b", "t", "t.timelapse", "w"]
    # The files, manifest included, byte for byte.
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "py").iterdir())
    assert "manifest.json" in names
    for name in names:
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes(), name
    # The arrays are those files' floats, rows north to south.
    for key in ("t", "w"):
        raw = np.fromfile(tmp_path / "cli" / f"{key}.r32", dtype="<f4").reshape(65, 65)
        hm = values[key]
        assert isinstance(hm, orogen.Heightmap)
        assert hm.height.dtype == np.float32 and hm.height.shape == (65, 65) == hm.shape
        assert np.array_equal(bits(hm.height), bits(raw))
        assert hm.cell == 20.0
    assert sorted(values["t"].layers) == ["eroded", "flow", "hardness", "sediment", "water"]
    # A time-lapse is a series of heightmaps: before the first step, every 10 steps and after the last.
    series = values["t.timelapse"]
    assert len(series) == 3 and series.times[0] == 0.0 and series.times == sorted(series.times)
    assert np.array_equal(bits(series[0].height), bits(values["w"].height))
    assert np.array_equal(bits(series[-1].height), bits(values["t"].height))
    with pytest.raises(IndexError):
        series[3]


def test_a_call_written_where_an_input_goes_is_not_a_named_value(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.orogen").write_text(
        "orogen 1\ngrid 33 cell=10\nb = generate:fault(iterations=10)\n"
        "w = erode:thermal(erode:thermal(b, iterations=2), iterations=3)\n")
    values = orogen.run("s.orogen")
    assert sorted(values) == ["b", "w"]


def test_arrays_are_read_only_views_that_outlive_the_result():
    values = orogen.run("orogen 1\ngrid 17\nb = generate:fault(iterations=5)\n")
    height = values["b"].height
    del values
    assert not height.flags.writeable and not height.flags.owndata  # a view of orogen's memory
    with pytest.raises(ValueError):
        height[0, 0] = 1.0
    assert np.isfinite(height).all() and height.std() > 0  # still alive after the result went
    copy = height.copy()
    copy[0, 0] = 1.0


def test_the_same_call_gives_the_same_bits_on_any_thread_count():
    spec = "orogen 1\nseed 3\ngrid 129\nb = generate:diamond-square()\nt = erode:thermal(b, iterations=30)\n"
    one = orogen.run(spec, threads=1)["t"]
    two = orogen.run(spec, threads=2)["t"]
    again = orogen.run(spec)["t"]
    assert np.array_equal(bits(one.height), bits(two.height))
    assert np.array_equal(bits(one.height), bits(again.height))
    assert np.array_equal(bits(one.layers["eroded"]), bits(two.layers["eroded"]))


def test_seed_and_set_act_as_the_cli_options(tmp_path):
    spec = "orogen 1\nseed 1\ngrid 33\nb = generate:fault(iterations=30, displacement=4)\nexport:raw(b, path=\"b.r32\")\n"
    (tmp_path / "s.orogen").write_text(spec)
    r = cli(["run", "s.orogen", "--out", "cli", "--quiet", "--seed", "9", "--set", "b.displacement=7.5",
             "--set", "b.iterations=12"], tmp_path)
    assert r.returncode == 0, r.stderr
    hm = orogen.run(str(tmp_path / "s.orogen"), seed=9, set={"b.displacement": 7.5, "b.iterations": 12})["b"]
    raw = np.fromfile(tmp_path / "cli" / "b.r32", dtype="<f4").reshape(33, 33)
    assert np.array_equal(bits(hm.height), bits(raw))
    assert not np.array_equal(bits(hm.height), bits(orogen.run(spec)["b"].height))


def test_without_out_nothing_is_written(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = set(os.listdir(tempfile.gettempdir()))
    values = orogen.run("orogen 1\ngrid 17\nb = generate:fault(iterations=5)\nexport:raw(b, path=\"b.r32\")\n")
    assert "b" in values
    assert list(tmp_path.iterdir()) == []
    assert not [n for n in set(os.listdir(tempfile.gettempdir())) - before if n.startswith("orogen-python-")]


def test_outputs_false_and_values_run_only_what_is_asked_for(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    whole = orogen.run(SPEC, out=str(tmp_path / "all"))
    # outputs=False: every named value, the same bits, and not one file even with out= given.
    quiet = orogen.run(SPEC, out=str(tmp_path / "none"), outputs=False)
    assert sorted(quiet) == sorted(whole)
    for name in whole:
        if hasattr(whole[name], "height"):
            assert np.array_equal(bits(quiet[name].height), bits(whole[name].height)), name
    assert not (tmp_path / "none").exists()
    # values=[...]: only those, and only the nodes they need run. A later node that would fail when it runs
    # (an export into a path that is a folder) is not reached.
    broken = SPEC + 'export:raw(t, path="dir.r32")\n'
    (tmp_path / "b" / "dir.r32").mkdir(parents=True)
    with pytest.raises(RuntimeError):
        orogen.run(broken, out=str(tmp_path / "b"))
    only = orogen.run(broken, out=str(tmp_path / "b"), values=["w"])
    assert list(only) == ["w"]
    assert np.array_equal(bits(only["w"].height), bits(whole["w"].height))
    with pytest.raises(ValueError, match=r"makes no value 'nope' \(it makes b, w, w.timelapse, t, t.timelapse\)"):
        orogen.run(SPEC, values=["nope"])


def test_bad_input_is_a_value_error_with_the_clis_message(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    bad = {
        "syntax.orogen": "orogen 1\ngrid 33\nb = generate:fault(iterations=\n",
        "range.orogen": "orogen 1\ngrid 33\nb = generate:fault(iterations=-3)\n",
        "unknown.orogen": "orogen 1\ngrid 33\nb = generate:faults()\n",
        "file.orogen": "orogen 1\ngrid 33\nd = import:exr(path=\"missing.exr\")\n",
    }
    for name, text in bad.items():
        (tmp_path / name).write_text(text)
        r = cli(["check", name], tmp_path)
        assert r.returncode == 2
        with pytest.raises(ValueError) as e:
            orogen.run(name)
        assert str(e.value) == r.stderr, name
    # The spec's own text: the same words, at the same line and column, in "<spec>".
    with pytest.raises(ValueError, match=r"<spec>:3:31: error: 'iterations' of generate:fault is -3, out of range"):
        orogen.run(bad["range.orogen"])
    with pytest.raises(ValueError, match="did you mean 'generate:fault'"):
        orogen.run(bad["unknown.orogen"])
    with pytest.raises(ValueError, match="unknown parameter|no node named|has no parameter"):
        orogen.run("orogen 1\ngrid 33\nb = generate:fault()\n", set={"b.nonsense": 3})
    with pytest.raises(ValueError, match="cannot give a parameter the Python value"):
        orogen.run("orogen 1\ngrid 33\nb = generate:fault()\n", set={"b.iterations": object()})
    with pytest.raises(ValueError, match="cannot read spec nowhere.orogen: no such file"):
        orogen.run("nowhere.orogen")
    with pytest.raises(TypeError, match="spec must be a str or a path"):
        orogen.run(42)
    with pytest.raises(ValueError, match="threads must be a number from 1 to 1024"):
        orogen.run("orogen 1\ngrid 17\nb = generate:fault()\n", threads=0)


def test_bad_input_met_while_running_is_a_value_error_and_a_failed_run_a_runtime_error(tmp_path):
    # A NaN in an imported file is found when the node reads it (exit 2 on the command line).
    nan = tmp_path / "nan.r32"
    np.array([1.0, float("nan"), 2.0, 3.0], dtype="<f4").tofile(nan)
    (tmp_path / "nan.r32.json").write_text('{"format": "r32", "width": 2, "height": 2, "cell_size": 1, '
                                           '"height_min": 0, "height_max": 3}')
    with pytest.raises(ValueError, match=r"node 'd' \(import:raw\) failed: .*not a finite number"):
        orogen.run(f"orogen 1\ngrid 9\nd = import:raw(path=\"{nan}\")\n")
    # A folder where an output goes: the run fails (exit 1), naming the node.
    (tmp_path / "out" / "b.r32").mkdir(parents=True)
    with pytest.raises(RuntimeError, match=r"node 'export:raw' \(export:raw\) failed: cannot write .*a folder has that name"):
        orogen.run("orogen 1\ngrid 17\nb = generate:fault(iterations=5)\nexport:raw(b, path=\"b.r32\")\n",
                   out=str(tmp_path / "out"))


def test_nodes_and_help_describe_the_loaded_plugins():
    names = {n["name"]: n for n in orogen.nodes()}
    for name in ("generate:fault", "erode:thermal", "export:exr", "import:exr", "render:terrain"):
        assert name in names and names[name]["summary"]
    h = orogen.help("erode:thermal")
    assert h["output"] == "heightmap" and h["inputs"][0]["type"] == "heightmap"
    talus = next(p for p in h["params"] if p["name"] == "talus")
    assert talus["type"] == "number" and talus["default"] == 35 and talus["unit"] == "°"
    assert (talus["min"], talus["max"], talus["min_exclusive"], talus["max_exclusive"]) == (0, 90, True, True)
    assert orogen.help("thermal")["name"] == "erode:thermal"
    with pytest.raises(ValueError, match="unknown node 'erode:thermle'; did you mean 'erode:thermal'"):
        orogen.help("erode:thermle")


def test_images_are_height_by_width_by_4_arrays():
    img = orogen.run("orogen 1\ngrid 33 cell=30\nb = generate:fault(iterations=20, displacement=5)\n"
                     "r = render:terrain(b, width=48, height=32)\n")["r"]
    assert img.shape == (32, 48, 4) and img.dtype == np.float32  # linear RGBA, as render:terrain makes it
    assert (img[..., 3] == 1).all() and img[..., :3].std() > 0


def test_the_gil_is_released_while_a_node_runs():
    spec = "orogen 1\ngrid 257\nb = generate:diamond-square()\nt = erode:thermal(b, iterations=8000)\n"
    ticks = 0
    done = threading.Event()

    def work():
        orogen.run(spec, threads=1)
        done.set()

    t = threading.Thread(target=work)
    start = time.monotonic()
    t.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    elapsed = time.monotonic() - start
    assert elapsed > 0.2, "the run was too short to tell"
    # Held, the GIL would let this loop tick once or twice at most; released, it ticks all along (hundreds of
    # times; at least 10 on the busiest machine).
    assert ticks >= 10, (ticks, elapsed)


def test_ctrl_c_stops_the_node_and_raises_keyboard_interrupt(tmp_path):
    spec = ("orogen 1\ngrid 513\nb = generate:diamond-square()\nt = erode:thermal(b, iterations=1000000)\n"
            "export:raw(t, path=\"t.r32\")\n")
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        orogen.run(spec, out=str(tmp_path / "out"))
    assert time.monotonic() - start < 10
    assert not (tmp_path / "out" / "t.r32").exists()


def test_a_thousand_calls_do_not_grow_memory():
    spec = "orogen 1\ngrid 33\nb = generate:fault(iterations=10)\nt = erode:thermal(b, iterations=2)\n"

    def rss_kib():
        with open("/proc/self/status") as f:
            return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))

    for _ in range(100):  # warm up: plugins loaded, allocator pools filled
        orogen.run(spec)["t"].height.sum()
    before = rss_kib()
    for _ in range(1000):
        orogen.run(spec)["t"].height.sum()
    grown = rss_kib() - before
    assert grown < 8 * 1024, f"RSS grew {grown} KiB over 1000 calls"


NODE_SPEC = """orogen 1
seed 4
grid 65x49 cell=10
b = generate:diamond-square(amplitude=200)
t = erode:thermal(b, talus=30, iterations=40)
"""


def test_node_on_a_numpy_array_gives_the_same_bits_as_the_node_in_a_spec():
    values = orogen.run(NODE_SPEC)
    made_by_numpy = np.array(values["b"].height)  # an ordinary, writable numpy array
    assert made_by_numpy.flags.owndata
    t = orogen.node("erode:thermal", made_by_numpy, cell=10, talus=30, iterations=40)
    assert isinstance(t, orogen.Heightmap) and t.shape == (49, 65) and t.cell == 10
    assert np.array_equal(bits(t.height), bits(values["t"].height))
    assert np.array_equal(bits(t.layers["eroded"]), bits(values["t"].layers["eroded"]))
    # A value from an earlier call, its layers carried through; and a generator on a grid, with the seed a
    # spec would give it.
    again = orogen.node("erode:thermal", values["b"], talus=30, iterations=40)
    assert np.array_equal(bits(again.height), bits(values["t"].height))
    b = orogen.node("generate:diamond-square", grid=(65, 49), cell=10, spec_seed=4, label="b", amplitude=200)
    assert np.array_equal(bits(b.height), bits(values["b"].height))
    # Layers go in and come back: erode:hydraulic on the thermal result keeps 'eroded' and adds its own.
    h = orogen.node("erode:hydraulic", t, iterations=3)
    assert {"eroded", "water", "sediment"} <= set(h.layers)


def test_node_refuses_what_the_checker_refuses_and_bad_arrays():
    a = np.zeros((9, 9), dtype=np.float32)
    with pytest.raises(ValueError, match=r"<spec>:5:38: error: 'talus' of erode:thermal is 95, out of range \(0, 90\)"):
        orogen.node("erode:thermal", a, talus=95)
    with pytest.raises(ValueError, match="erode:thermal has no parameter 'nonsense'"):
        orogen.node("erode:thermal", a, nonsense=1)
    with pytest.raises(ValueError, match="unknown node|did you mean"):
        orogen.node("erode:thermle", a)
    with pytest.raises(ValueError, match="input 1 is float64; orogen heightmaps are float32"):
        orogen.node("erode:thermal", a.astype(np.float64))
    with pytest.raises(ValueError, match=r"input 1 has shape \(9,\); a heightmap is a 2-D array"):
        orogen.node("erode:thermal", a[0])
    nan = a.copy()
    nan[2, 5] = np.nan
    with pytest.raises(ValueError, match=r"input 1: sample \(5, 2\) is nan; heights and layers must be finite"):
        orogen.node("erode:thermal", nan)
    with pytest.raises(ValueError, match="cell must be a number of metres above 0"):
        orogen.node("erode:thermal", a, cell=-1)
    with pytest.raises(ValueError, match="cannot give a parameter the Python value"):
        orogen.node("erode:thermal", a, talus=object())


def test_plates_and_particles_come_back_frame_by_frame():
    values = orogen.run("orogen 1\nseed 2\ngrid 65 cell=100\nc = generate:fault(iterations=10)\n"
                        "p = tectonics:plates(c, plates=4, steps=60, record_every=20)\n"
                        "s = erode:sph(c, steps=12, particles=2000, rain=20, record_every=4)\n")
    plates = values["p.plates"]
    assert plates["width"] > 0 and plates["height"] > 0 and len(plates["snapshots"]) >= 2
    first = plates["snapshots"][0]["plates"][0]
    assert first["polygon"].shape[1] == 2 and first["polygon"].shape[0] >= 3
    assert isinstance(first["velocity"], tuple) and len(first["velocity"]) == 2
    frames = values["s.particles"]
    assert len(frames) >= 3
    last = frames[-1]
    position = last["attributes"]["position"]
    assert position.dtype == np.float32 and position.ndim == 2 and position.shape[1] == 3 and position.shape[0] > 0
    assert not position.flags.writeable
    assert all(a.shape[0] == position.shape[0] for a in last["attributes"].values())
    assert [f["step"] for f in frames] == sorted(f["step"] for f in frames)


def test_node_writes_no_file_not_even_a_temporary_one(tmp_path, monkeypatch):
    # $TMPDIR (and Python's own tempfile folder) a regular file: a temporary file or folder anywhere under it
    # could not be made, so a call that made one would fail. The inputs are handed over in memory.
    not_a_folder = tmp_path / "not-a-folder"
    not_a_folder.write_text("")
    monkeypatch.setenv("TMPDIR", str(not_a_folder))
    monkeypatch.setattr(tempfile, "tempdir", str(not_a_folder))
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    a = (np.arange(33 * 33, dtype=np.float32).reshape(33, 33) % 7) * 3
    t = orogen.node("erode:thermal", a, iterations=3)
    h = orogen.node("erode:hydraulic", t, iterations=2)
    g = orogen.node("generate:fault", grid=(17, 17), iterations=3)
    assert t.shape == h.shape == (33, 33) and g.shape == (17, 17)
    assert not np.array_equal(t.height, a)
    # run() too, when no node of the spec writes a file.
    assert orogen.run("orogen 1\ngrid 17\nb = generate:fault(iterations=5)\n")["b"].shape == (17, 17)
    assert list(cwd.iterdir()) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cwd", "not-a-folder"]
    assert not_a_folder.read_text() == ""


def test_a_heightmaps_layers_reach_the_node_intact_and_the_value_is_not_changed():
    values = orogen.run(NODE_SPEC + "h = erode:hydraulic(t, iterations=3)\nu = erode:thermal(h, talus=30, iterations=5)\n")
    h = values["h"]
    height, layers = h.height.copy(), {k: v.copy() for k, v in h.layers.items()}
    assert {"eroded", "sediment", "water"} <= set(layers)
    u = orogen.node("erode:thermal", h, spec_seed=4, label="u", talus=30, iterations=5)
    want = values["u"]
    assert sorted(u.layers) == sorted(want.layers) and set(layers) <= set(u.layers)
    assert np.array_equal(bits(u.height), bits(want.height))
    for name in want.layers:
        assert np.array_equal(bits(u.layers[name]), bits(want.layers[name])), name
    # The node changed a copy: the earlier value, which Python still holds, is as it was.
    assert np.array_equal(bits(h.height), bits(height))
    for name, layer in layers.items():
        assert np.array_equal(bits(h.layers[name]), bits(layer)), name
    with pytest.raises(ValueError, match="'input1' is a value the caller hands to the run"):
        orogen.node("erode:thermal", h, label="input1")


def test_node_reads_fortran_order_and_strided_arrays_and_leaves_them_as_they_were():
    values = orogen.run(NODE_SPEC)
    c = np.array(values["b"].height)
    fortran = np.asfortranarray(c)
    wide = np.full((49 * 2, 65 * 3), 7.0, dtype=np.float32)
    wide[::2, ::3] = c
    strided = wide[::2, ::3]
    assert not fortran.flags.c_contiguous and not strided.flags.c_contiguous and not strided.flags.f_contiguous
    for a in (fortran, strided, c):
        t = orogen.node("erode:thermal", a, cell=10, talus=30, iterations=40)
        assert np.array_equal(bits(t.height), bits(values["t"].height))
        assert np.array_equal(bits(a), bits(values["b"].height))  # the caller's array untouched
    wide[4, 9] = np.inf  # sample (3, 2) of the strided view
    with pytest.raises(ValueError, match=r"input 1: sample \(3, 2\) is inf; heights and layers must be finite"):
        orogen.node("erode:thermal", strided)


MODEL_SPEC = """orogen 1
seed 3
grid 97 cell=30
b = generate:diamond-square(roughness=0.6, amplitude=300)
r = erode:evolve(b, years=5e4, dt=1e4, open="ns") {
    uplift(rate=2)
    flow()
    creep(diffusivity=0.5)
    stream-power(erodibility=2e-5, m=0.5)
    landslides(angle=35)
}
"""

BODY = [("uplift", {"rate": 2}), ("flow", {}), ("creep", {"diffusivity": 0.5}),
        ("stream-power", {"erodibility": 2e-5, "m": 0.5}), ("landslides", {"angle": 35})]


def test_a_model_stepped_from_python_gives_the_bits_of_the_same_body_in_a_spec():
    values = orogen.run(MODEL_SPEC)
    model = orogen.Model(values["b"], BODY, open="ns", seed=3, label="r")
    for _ in range(5):
        model.step(1e4)
    assert model.time == 5e4
    result = model.result()
    assert np.array_equal(bits(result.height), bits(values["r"].height))
    assert np.array_equal(bits(result.layers["drainage"]), bits(values["r"].layers["drainage"]))
    assert "elevation" in model.fields and "uplifted" in model.fields
    # 2 mm/yr for 5e4 yr on every cell but the open sides' (base level)
    assert np.allclose(model["uplifted"][1:-1, :], 100.0)


def test_a_field_written_between_steps_is_what_the_next_step_starts_from():
    values = orogen.run(MODEL_SPEC)
    a = orogen.Model(values["b"], BODY, open="ns", seed=3, label="r")
    b = orogen.Model(values["b"], BODY, open="ns", seed=3, label="r")
    a.step(1e4)
    b.step(1e4)
    z = b["elevation"]
    assert z.dtype == np.float64 and z.shape == (97, 97)
    b["elevation"] = np.minimum(z, np.median(z))  # plane the upper half off
    a.step(1e4)
    b.step(1e4)
    assert b["elevation"].max() < a["elevation"].max() - 10
    with pytest.raises(KeyError, match="no field 'soil' in this model"):
        b["soil"]
    with pytest.raises(ValueError, match="does not match"):
        b["elevation"] = np.zeros((3, 3))


def test_a_model_is_checked_as_a_spec_is():
    flat = np.zeros((33, 33), dtype=np.float32)
    with pytest.raises(ValueError, match="unknown process 'creap'; did you mean 'creep'"):
        orogen.Model(flat, [("flow", {}), ("creap", {})], cell=30)
    with pytest.raises(ValueError, match="stream-power reads the flow graph"):
        orogen.Model(flat, [("stream-power", {})], cell=30)
    with pytest.raises(ValueError, match="out of range"):
        orogen.Model(flat, [("flow", {}), ("stream-power", {"m": 9})], cell=30)


def test_import_without_numpy_says_which_interpreter_and_the_fix():
    # numpy hidden from a fresh interpreter, as on one it was never installed for
    code = "import sys; sys.modules['numpy'] = None; import orogen"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=dict(os.environ))
    assert r.returncode != 0
    assert "orogen needs numpy, which " + sys.executable + " cannot import" in r.stderr, r.stderr
    assert "run /usr/bin/python3, or install numpy for this one" in r.stderr
