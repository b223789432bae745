"""Shared fixtures: where the CLI and the scenarios are (set by CTest, python/CMakeLists.txt)."""
import os
import subprocess

import pytest

SOURCE_DIR = os.environ.get("GRASPSIM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.environ.get("GRASPSIM_CLI", os.path.join(SOURCE_DIR, "build", "tools", "graspsim"))
LIFT = os.path.join(SOURCE_DIR, "scenarios", "two_finger_lift.lua")


def cli(*args):
    """Runs the graspsim CLI; returns the finished process (its exit status unchecked)."""
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)


def same_trace(a, b):
    """`graspsim compare --bitwise --all-ticks`: exit 0 when both hold the same ticks, with the same bits."""
    p = cli("compare", a, b, "--bitwise", "--all-ticks")
    assert p.returncode == 0, p.stdout + p.stderr


@pytest.fixture
def lift():
    return LIFT
