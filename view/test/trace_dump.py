#!/usr/bin/python3
"""What the browser test compares the page with, read by h5py (not by graspsim's own reader):
every /physics row's tick, each body's position, quaternion, grasp area and torsion, and each
finger's /haptic tick, contact state, contacted body, god-object, force, surface point, depth and
friction radius, and its HIP from the /servo row at each haptic tick; where the trace recorded
/contacts, its rows (tick, a, b, point, force), each body's mass and gravity (from the root
attribute `parameters`). Usage: trace_dump.py TRACE.h5 -> JSON on stdout. A cut trace is opened in
SWMR mode, as recordings/README.md says h5py must."""
import json
import sys

import h5py


def columns(table):
    """{column: array} of a table, its rows read once: a member is a column (schema 3,
    "objects/box/position"); a member that is an array of compound elements (schema 4) is a group
    of entities, named by the table's attribute of the member's name (one a line), field f of
    entity e being column "<member>/<e>/<f>"."""
    rows = table[:]
    out = {}
    for member in rows.dtype.names:
        sub = rows.dtype[member].subdtype
        if sub is None or sub[0].names is None:
            out[member] = rows[member]
            continue
        names = table.attrs[member]
        names = (names if isinstance(names, str) else names.decode()).split("\n")
        for k, entity in enumerate(names):
            for field in sub[0].names:
                out[f"{member}/{entity}/{field}"] = rows[member][:, k][field]
    return out


def main(path):
    with h5py.File(path, "r", swmr=True) as f:
        physics = columns(f["physics"])
        haptic = columns(f["haptic"])
        servo = columns(f["servo"])
        servo_row = {int(t): i for i, t in enumerate(servo["tick"])}
        at_haptic = [servo_row.get(int(t), 0) for t in haptic["tick"]]
        bodies = sorted({n.split("/")[1] for n in physics if n.startswith("objects/")})
        fingers = sorted({n.split("/")[1] for n in haptic if n.startswith("fingers/")})
        out = {
            "status": f.attrs["status"] if isinstance(f.attrs["status"], str) else f.attrs["status"].decode(),
            "physics_tick": physics["tick"].tolist(),
            "bodies": {b: {"position": physics[f"objects/{b}/position"].tolist(),
                           "quaternion": physics[f"objects/{b}/quaternion"].tolist(),
                           "grasp_area": physics[f"objects/{b}/grasp_area"].tolist(),
                           "torsion": physics[f"objects/{b}/torsion"].tolist(),
                           "velocity": physics[f"objects/{b}/velocity"].tolist()} for b in bodies},
            "haptic_tick": haptic["tick"].tolist(),
            "fingers": {n: {"state": haptic[f"fingers/{n}/state"].tolist(),
                            "surface_point": haptic[f"fingers/{n}/surface_point"].tolist(),
                            "friction_radius": haptic[f"fingers/{n}/friction_radius"].tolist(),
                            "depth": haptic[f"fingers/{n}/depth"].tolist(),
                            "body": haptic[f"fingers/{n}/body"].tolist(),
                            "god_object": haptic[f"fingers/{n}/god_object"].tolist(),
                            "force": haptic[f"fingers/{n}/force"].tolist(),
                            "hip": servo[f"fingers/{n}/hip"][at_haptic].tolist()} for n in fingers},
        }
        if "contacts" in f:
            c = f["contacts"][:]
            out["contacts"] = {k: c[k].tolist() for k in ("tick", "a", "b", "point", "force")}
            params = f.attrs["parameters"]
            params = params if isinstance(params, str) else params.decode()
            values = dict(line.split(" = ", 1) for line in params.splitlines() if " = " in line)
            out["mass"] = {b: float(values[f"objects.{b}.mass"]) for b in bodies}
            out["gravity"] = [float(x) for x in values["gravity"].split(",")]
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main(sys.argv[1])
