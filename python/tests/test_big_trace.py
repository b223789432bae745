"""Traces as big as the scenes read from Python: 1000 bodies and 100 fingers
(tests/e2e/data/many_bodies.lua, the scene tests/e2e/test_big_trace.cpp runs, compares and
replays), run from Python and read back by read_trace as numpy, one array per column."""
import os

import numpy as np

import graspsim
from conftest import SOURCE_DIR, cli, same_trace

SCENE = os.path.join(SOURCE_DIR, "tests", "e2e", "data", "many_bodies.lua")


def test_a_trace_of_1000_bodies_reads_as_numpy(tmp_path):
    # One physics tick (0.02 s at 50 Hz): what is read is the width of the rows, not their number.
    s = graspsim.load(SCENE, set={"objects": 1000, "duration": 0.02}, trace=tmp_path / "bodies.h5")
    assert len(s.bodies) == 1000
    result = s.run()
    assert result["error"] == "" and result["physics_ticks"] == 1, result
    t = graspsim.read_trace(tmp_path / "bodies.h5")
    physics = [k for k in t if k.startswith("/physics/")]
    assert len(physics) == 3 + 1000 * 11   # tick, time, state_hash and 11 columns a body
    position = t["/physics/objects/box999/position"]
    assert position.shape == (1, 3) and position.dtype == np.float64
    # Box 999 of a 32 x 32 grid 0.3 m apart: row 31, column 7, where it was put.
    assert np.allclose(position[0, :2], [(7 - 15.5) * 0.3, (31 - 15.5) * 0.3], atol=1e-9)
    assert t["/physics/objects/box0/floor_contacts"].dtype == np.int32
    assert t["/physics/state_hash"].dtype == np.uint64
    assert graspsim.trace_attribute(tmp_path / "bodies.h5", "units", "/physics/objects/box7/velocity") == "m/s"


def test_a_trace_of_100_fingers_reads_as_numpy_and_equals_the_cli(tmp_path):
    sets = {"objects": 4, "fingers": 100}
    graspsim.load(SCENE, set=sets, trace=tmp_path / "py.h5").run()
    t = graspsim.read_trace(tmp_path / "py.h5")
    assert len([k for k in t if k.startswith("/servo/fingers/")]) == 100 * 4
    assert len([k for k in t if k.startswith("/haptic/fingers/")]) == 100 * 8
    assert t["/servo/fingers/f99/hip"].shape == (300, 3)
    assert t["/haptic/fingers/f99/body"][-1] == 3   # finger 99 presses on the fourth box
    p = cli("run", SCENE, "--set", "objects=4", "--set", "fingers=100", "--out", tmp_path / "cli.h5", "--quiet")
    assert p.returncode == 0, p.stdout + p.stderr
    same_trace(tmp_path / "cli.h5", tmp_path / "py.h5")
