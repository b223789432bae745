"""Bad input raises a graspsim.Error naming the file and line, the field or the argument."""
import os
import stat

import pytest

import graspsim
from conftest import LIFT


def test_a_missing_scenario_file_is_named(tmp_path):
    missing = tmp_path / "nowhere.lua"
    with pytest.raises(graspsim.ScenarioError, match="nowhere.lua"):
        graspsim.load(missing)


def test_a_bad_set_field_is_named():
    with pytest.raises(graspsim.ScenarioError, match="objects.box.nosuch"):
        graspsim.load(LIFT, set={"objects.box.nosuch": 1})
    with pytest.raises(graspsim.ScenarioError, match="objects.box.nosuch"):
        graspsim.load(LIFT, set=["objects.box.nosuch=1"])
    with pytest.raises(ValueError, match="'mass' is not NAME=VALUE"):
        graspsim.load(LIFT, set=["mass"])
    with pytest.raises(TypeError, match="a dict"):
        graspsim.load(LIFT, set="mass=1")


def test_bad_lua_is_named_with_its_file_and_line(tmp_path):
    bad = tmp_path / "bad.lua"
    bad.write_text("return {\n  name = 'bad',\n  duration = = 1,\n}\n")
    with pytest.raises(graspsim.ScenarioError, match=r"bad\.lua:3"):
        graspsim.load(bad)
    assert issubclass(graspsim.ScenarioError, graspsim.Error)


def test_a_script_error_during_the_run_is_named_and_marks_the_trace(tmp_path):
    # The lift with the thumb's trajectory a function that fails at t >= 0.5 s (line 5 below).
    source = open(LIFT).read().replace(
        "{ name = \"thumb\", stiffness = 400, damping = 4, max_force = 10, trajectory = path(-1) }",
        "{ name = \"thumb\", stiffness = 400, damping = 4, max_force = 10,\n"
        "  trajectory = function(t)\n"
        "    if t < 0.5 then return { -0.1, 0, 0.03 } end\n"
        "    error('thumb lost')\n"
        "  end }")
    assert "thumb lost" in source
    failing = tmp_path / "failing.lua"
    failing.write_text(source)
    s = graspsim.load(failing, trace=tmp_path / "f.h5")
    with pytest.raises(graspsim.RunError, match=r"failing\.lua:\d+.*thumb lost"):
        s.run()
    assert s.done
    assert graspsim.trace_attribute(tmp_path / "f.h5", "status").startswith("error: ")


def test_the_output_may_not_be_an_input_and_is_left_as_it_was(tmp_path):
    scenario = tmp_path / "lift.lua"
    scenario.write_text(open(LIFT).read())
    before = scenario.read_bytes()
    with pytest.raises(graspsim.OutputError, match="lift.lua"):
        graspsim.load(scenario, trace=scenario)
    assert scenario.read_bytes() == before
    with pytest.raises(ValueError, match="record"):
        graspsim.load(LIFT, record="physics")          # no trace to record into
    with pytest.raises(ValueError, match="record 'nosuch'"):
        graspsim.load(LIFT, trace=tmp_path / "x.h5", record="nosuch")
    assert not os.path.exists(tmp_path / "x.h5")


def test_a_trace_path_that_is_not_a_regular_file_is_refused(tmp_path):
    # A trace is written beside its path and renamed over it: a FIFO, a socket, a device or a
    # directory there is refused, named, with how to write no trace; it is left as it was.
    fifo = tmp_path / "fifo.h5"
    os.mkfifo(fifo)
    with pytest.raises(graspsim.OutputError, match=r"trace '.*fifo\.h5' is a FIFO.*trace=None writes no trace"):
        graspsim.load(LIFT, trace=fifo)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert not os.path.exists(str(fifo) + ".partial")
    folder = tmp_path / "folder"
    folder.mkdir()
    with pytest.raises(graspsim.OutputError, match="is a directory"):
        graspsim.load(LIFT, trace=folder)
    assert os.listdir(folder) == []


def test_a_file_that_is_not_a_trace_is_named(tmp_path):
    junk = tmp_path / "junk.h5"
    junk.write_text("not HDF5")
    with pytest.raises(graspsim.TraceError, match="junk.h5"):
        graspsim.read_trace(junk)


def test_a_device_that_cannot_open_writes_nothing(tmp_path):
    # The thumb's default device replays a file that is not a trace: the run cannot start, and
    # the file already at the trace's path is left as it was (as `graspsim run` exits 2).
    junk = tmp_path / "junk.h5"
    junk.write_text("not HDF5")
    source = open(LIFT).read().replace(
        "trajectory = path(-1) }", "trajectory = path(-1), device = { default = \"replay:%s\" } }" % junk)
    assert "replay:" in source
    scenario = tmp_path / "device.lua"
    scenario.write_text(source)
    out = tmp_path / "out.h5"
    out.write_text("kept")
    with pytest.raises(graspsim.DeviceError, match="could not start.*junk.h5"):
        graspsim.load(scenario, trace=out)
    assert out.read_text() == "kept" and not os.path.exists(str(out) + ".partial")


def test_a_session_is_refused_to_other_threads_while_it_steps():
    # step() releases the GIL; any other call on the session meanwhile would race with the run, so
    # it raises RuntimeError "session is busy". 40 s of the lift (480000 ticks, no trace) keeps the
    # stepping thread busy long enough for this thread to try; afterwards the session answers.
    import threading

    s = graspsim.load(LIFT, set={"duration": 40})
    stepper = threading.Thread(target=s.step, args=(s.ticks,))
    refused = None
    stepper.start()
    while stepper.is_alive() and refused is None:
        try:
            s.state()
        except RuntimeError as e:
            refused = str(e)
    stepper.join()
    assert refused is not None and "session is busy" in refused
    assert s.tick == s.ticks
    assert s.finish()["passed"] in (True, False)
