"""A HIP set from Python moves the god-object and the force as the friction cone says."""
import os

import numpy as np
import pytest

import graspsim
from conftest import LIFT, cli

FLOOR = os.path.join(os.path.dirname(__file__), "finger_on_floor.lua")
K = 400.0    # N/m: the finger's stiffness (the rigid floor adds no spring in series)
MU = 0.5     # the floor's friction, static = kinetic
D = 0.004    # m: how deep the test presses the HIP into the floor


def press(s, hip):
    """Sets the HIP and runs one haptic period (6 servo ticks at 3000 / 500 Hz)."""
    s.set_hip("finger", hip)
    assert s.step(6) == 6
    return s.records()


def test_a_hip_set_from_python_follows_the_friction_cone():
    # The paper's friction cone (section 2): pressed to depth d, the god-object (GO) stays where
    # the finger entered while the HIP's surface point SP is within mu d of it (stick); beyond,
    # the GO is dragged onto the circle of radius mu d about SP (slip). The force on the finger is
    # k (GO - HIP): k d normal, and tangentially k |GO - SP|, at most mu k d: the cone's edge.
    with graspsim.load(FLOOR, drive=["finger"]) as s:
        s.step(6)                                       # the trajectory's HIP, 1 cm above: free
        assert s.records()["haptic"]["touching"] == [""]
        r = press(s, [0, 0, -D])                        # enters the floor at the origin
        assert r["haptic"]["touching"] == ["floor"]
        assert np.allclose(r["haptic"]["god_object"][0], [0, 0, 0], atol=1e-15)
        assert r["haptic"]["friction_radius"][0] == pytest.approx(MU * D, rel=1e-12)
        assert np.allclose(r["servo"]["force"][0], [0, 0, K * D], rtol=1e-12, atol=1e-12)

        r = press(s, [0.001, 0, -D])                    # 1 mm < mu d = 2 mm: sticks
        assert r["haptic"]["phase"][0] == 1             # stick
        assert np.allclose(r["haptic"]["god_object"][0], [0, 0, 0], atol=1e-15)
        assert np.allclose(r["servo"]["force"][0], [-K * 0.001, 0, K * D], rtol=1e-12, atol=1e-12)

        r = press(s, [0.003, 0, -D])                    # 3 mm > 2 mm: slips to 2 mm behind SP
        assert r["haptic"]["phase"][0] == 2             # slip
        assert np.allclose(r["haptic"]["god_object"][0], [0.003 - MU * D, 0, 0], atol=1e-15)
        f = r["servo"]["force"][0]
        assert np.allclose(f, [-K * MU * D, 0, K * D], rtol=1e-12, atol=1e-12)
        assert np.hypot(f[0], f[1]) == pytest.approx(MU * f[2], rel=1e-12)   # on the cone
        assert np.allclose(s.hip("finger"), [0.003, 0, -D], atol=0)
        assert np.allclose(s.rendered_force("finger"), f, atol=1e-12)   # under max_force 10 N

        s.follow_trajectory("finger")                   # its trajectory again: 1 cm above, free
        s.step(6)
        assert np.array_equal(s.hip("finger"), [0, 0, 0.01])
        assert s.records()["haptic"]["touching"] == [""]


def test_only_driven_fingers_take_a_hip():
    s = graspsim.load(LIFT)
    with pytest.raises(ValueError, match="'thumb' follows its scenario's device.*drive="):
        s.set_hip("thumb", [0, 0, 0])
    with pytest.raises(ValueError, match=r"no finger 'pinky'.*fingers: thumb, index"):
        s.hip("pinky")
    with pytest.raises(ValueError, match=r"no finger 'pinky'.*fingers: thumb, index"):
        graspsim.load(LIFT, drive=["pinky"])
    d = graspsim.load(LIFT, drive=["thumb"])
    with pytest.raises(ValueError, match="finite"):
        d.set_hip("thumb", [0, float("nan"), 0])
    with pytest.raises(ValueError, match="three numbers"):
        d.set_hip("thumb", [0, 0])


def test_a_python_driven_session_replays_bit_for_bit(tmp_path):
    # A driven finger's samples go to /devices/<finger>, so `graspsim replay` feeds them back and
    # must reproduce the session (it compares the new trace with the recording, exit 0 if equal).
    s = graspsim.load(LIFT, trace=tmp_path / "driven.h5", drive=["thumb"])
    s.step(3600)                                          # t = 1.2 s: gripping
    s.set_hip("thumb", s.hip("thumb") + [0.002, 0, 0])    # 2 mm deeper into the box
    s.step(300)
    s.follow_trajectory("thumb")
    assert s.run()["error"] == ""
    assert graspsim.trace_attribute(tmp_path / "driven.h5", "devices").startswith("thumb: program")
    p = cli("replay", tmp_path / "driven.h5", "--out", tmp_path / "replay.h5")
    assert p.returncode == 0 and "bit for bit" in p.stdout, p.stdout + p.stderr
