"""A run stepped from Python writes the CLI's trace; its state, records and trace read as numpy."""
import numpy as np

import graspsim
from conftest import LIFT, cli, same_trace


def test_python_lift_equals_the_cli_trace_bit_for_bit(tmp_path):
    # The same scenario run by the CLI and by run() goes through the same RunSession, so every
    # dataset must hold the same bits (only root attributes such as wall time may differ).
    assert cli("run", LIFT, "--out", tmp_path / "cli.h5", "--quiet").returncode == 0
    result = graspsim.load(LIFT, trace=tmp_path / "py.h5").run()
    assert result["passed"], result
    assert result["trace"] == str(tmp_path / "py.h5")
    assert result["servo_ticks"] == 12000   # 4 s at 3000 Hz
    same_trace(tmp_path / "cli.h5", tmp_path / "py.h5")


def test_set_overrides_equal_the_cli_set(tmp_path):
    # A dict value crosses as --set's text: 0.9 as "0.9", a list joined by commas. A heavier box
    # and a stronger grip change the run, so equality shows the overrides were applied alike.
    sets = {"mass": 0.5, "squeeze": 0.012, "gravity": [0, 0, -9.8]}
    p = cli("run", LIFT, "--out", tmp_path / "cli.h5", "--quiet",
            "--set", "mass=0.5", "--set", "squeeze=0.012", "--set", "gravity=0,0,-9.8")
    assert p.returncode in (0, 1), p.stderr
    graspsim.load(LIFT, set=sets, trace=tmp_path / "py.h5").run()
    same_trace(tmp_path / "cli.h5", tmp_path / "py.h5")
    plain = graspsim.load(LIFT, trace=tmp_path / "plain.h5")
    plain.run()
    assert cli("compare", tmp_path / "py.h5", tmp_path / "plain.h5").returncode == 1


def test_stepping_tick_by_tick_equals_run(tmp_path):
    # step() one tick at a time is run() cut into calls: the same ticks in the same order.
    stepped = graspsim.load(LIFT, trace=tmp_path / "stepped.h5")
    ticks = 0
    while stepped.step():
        ticks += 1
    assert ticks == stepped.ticks == 12000 and stepped.done
    a = stepped.finish()
    b = graspsim.load(LIFT, trace=tmp_path / "run.h5").run()
    assert a["expectations"] == b["expectations"]
    same_trace(tmp_path / "stepped.h5", tmp_path / "run.h5")


def test_records_and_state_agree_with_the_trace(tmp_path):
    # The records Python reads after a physics tick are the rows the trace gets for that tick.
    s = graspsim.load(LIFT, trace=tmp_path / "t.h5")
    assert s.tick == 0 and s.time == 0.0
    assert s.step(3000) == 3000    # ticks 0 to 2999
    assert s.step() == 1           # tick 3000 (t = 1 s): physics every 60 servo ticks (3000 / 50 Hz)
    rec = s.records()
    assert rec["physics_ran"] and rec["tick"] == 3000
    assert s.tick == 3001 and s.time == 3001 / 3000
    position = rec["physics"]["position"].copy()
    god_object = rec["haptic"]["god_object"].copy()
    assert rec["haptic"]["touching"] == ["box", "box"]   # gripped by t = 1 s
    st = s.state()
    assert st["bodies"]["position"].shape == (1, 3) and st["bodies"]["rotation"].shape == (1, 3, 3)
    assert np.allclose(st["bodies"]["rotation"][0] @ st["bodies"]["rotation"][0].T, np.eye(3))
    # A physics tick records the state before its step, so the state now is that record only
    # where the box did not move: its orientation (the grip holds it level to round-off).
    assert np.allclose(st["bodies"]["orientation"][0], rec["physics"]["orientation"][0], atol=1e-9)
    s.finish()
    t = graspsim.read_trace(tmp_path / "t.h5")
    row = int(np.flatnonzero(t["/physics/tick"] == 3000)[0])
    assert np.array_equal(t["/physics/objects/box/position"][row], position[0])
    hrow = int(np.flatnonzero(t["/haptic/tick"] == 3000)[0])
    assert np.array_equal(t["/haptic/fingers/thumb/god_object"][hrow], god_object[0])
    assert t["/physics/tick"].dtype == np.int64
    assert graspsim.trace_attribute(tmp_path / "t.h5", "status") == "complete"


def test_no_trace_writes_nothing_and_checks_the_same(tmp_path, monkeypatch):
    # trace=None (the default) is --no-trace: no file, and the same expectations as a traced run.
    monkeypatch.chdir(tmp_path)
    result = graspsim.load(LIFT).run()
    assert result["trace"] is None and list(tmp_path.iterdir()) == []
    assert [e["passed"] for e in result["expectations"]] == [True] * len(result["expectations"])


def test_finish_early_reports_later_expectations_not_checked(tmp_path):
    # Ended at t = 1 s, before the grip check at 1.5 s and the end: nothing was checked.
    with graspsim.load(LIFT, trace=tmp_path / "cut.h5") as s:
        s.step(3000)
    result = s.finish()
    assert not result["passed"]
    assert all(e["detail"].startswith("not checked") for e in result["expectations"])
    assert graspsim.read_trace(tmp_path / "cut.h5")["/servo/tick"][-1] == 2999


def test_numpy_and_other_number_types_cross_as_their_value(tmp_path):
    # np.int64 is not a Python int, and under numpy 2 repr(np.float64(0.5)) is "np.float64(0.5)":
    # a set value is converted as a number (int() or float()), never by its repr. Floor, a float
    # subclass whose repr is not its digits, stands for numpy 2's scalars on numpy 1. Both runs
    # must be the plain-number run bit for bit.
    class Floor(float):
        def __repr__(self):
            return "Floor(%r)" % float(self)

    plain = {"mass": 0.5, "squeeze": 0.012, "gravity": [0, 0, -9.8]}
    numpy_set = {"mass": np.float64(0.5), "squeeze": np.float64(0.012),
                 "gravity": [np.int64(0), np.int32(0), np.float64(-9.8)]}
    subclass_set = {"mass": Floor(0.5), "squeeze": Floor(0.012), "gravity": np.array([0, 0, -9.8])}
    graspsim.load(LIFT, set=plain, trace=tmp_path / "plain.h5").run()
    graspsim.load(LIFT, set=numpy_set, trace=tmp_path / "numpy.h5").run()
    graspsim.load(LIFT, set=subclass_set, trace=tmp_path / "subclass.h5").run()
    same_trace(tmp_path / "plain.h5", tmp_path / "numpy.h5")
    same_trace(tmp_path / "plain.h5", tmp_path / "subclass.h5")
