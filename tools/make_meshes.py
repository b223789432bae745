#!/usr/bin/env python3
"""Writes the small meshes in scenarios/meshes/ (run from anywhere; deterministic output).

  octahedron.obj  convex: a regular octahedron of circumradius 3 cm (8 triangles, v//vn forms)
  ring.obj        mesh: a ring of square section 12 x 12 mm swept round a 16-gon of radius
                  3 cm (a handle, genus 1, 128 triangles as 64 quads)
  wedge_mm.stl    convex, binary STL in millimetres whose 80-byte header starts with "solid"
                  (as many exporters write it): a right triangular prism, legs 40 and 30 mm,
                  20 mm thick (8 triangles)
"""
import math
import os
import struct

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenarios", "meshes")


def octahedron(path):
    r = 0.03
    v = [(r, 0, 0), (-r, 0, 0), (0, r, 0), (0, -r, 0), (0, 0, r), (0, 0, -r)]
    # Counter-clockwise seen from outside (1-based indices).
    f = [(1, 3, 5), (3, 2, 5), (2, 4, 5), (4, 1, 5), (3, 1, 6), (2, 3, 6), (4, 2, 6), (1, 4, 6)]
    with open(path, "w") as out:
        out.write("# octahedron, circumradius 0.03 m (tools/make_meshes.py)\no octahedron\n")
        for p in v:
            out.write("v %.17g %.17g %.17g\n" % p)
        out.write("vn 0 0 1\n")
        for t in f:
            out.write("f %d//1 %d//1 %d//1\n" % t)


def ring(path):
    n, big, a = 16, 0.03, 0.006
    section = [(big - a, -a), (big + a, -a), (big + a, a), (big - a, a)]   # (r, z), ccw
    with open(path, "w") as out:
        out.write("# ring of square section 2a = 12 mm round a 16-gon of radius 30 mm "
                  "(tools/make_meshes.py)\ng ring\n")
        for i in range(n):
            phi = 2 * math.pi * i / n
            for (r, z) in section:
                out.write("v %.17g %.17g %.17g\n" % (r * math.cos(phi), r * math.sin(phi), z))
        for i in range(n):
            j = (i + 1) % n
            for k in range(4):
                l = (k + 1) % 4
                # Quad between section edge k -> l at angles i and j, outward.
                out.write("f %d %d %d %d\n" % (4 * i + k + 1, 4 * j + k + 1, 4 * j + l + 1, 4 * i + l + 1))


def wedge(path):
    # Triangle (0,0), (40,0), (0,30) in xy (mm), z in [0, 20].
    tri = [(0, 0), (40, 0), (0, 30)]
    lo = [(x, y, 0.0) for x, y in tri]
    hi = [(x, y, 20.0) for x, y in tri]
    faces = [(hi[0], hi[1], hi[2]), (lo[0], lo[2], lo[1])]
    for i in range(3):
        j = (i + 1) % 3
        faces += [(lo[i], lo[j], hi[j]), (lo[i], hi[j], hi[i])]
    with open(path, "wb") as out:
        out.write(b"solid wedge, binary, millimetres (tools/make_meshes.py)".ljust(80, b" "))
        out.write(struct.pack("<I", len(faces)))
        for f in faces:
            out.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for p in f:
                out.write(struct.pack("<3f", *p))
            out.write(struct.pack("<H", 0))


if __name__ == "__main__":
    os.makedirs(HERE, exist_ok=True)
    octahedron(os.path.join(HERE, "octahedron.obj"))
    ring(os.path.join(HERE, "ring.obj"))
    wedge(os.path.join(HERE, "wedge_mm.stl"))
