-- One object of every shape, falling freely (no floor, no fingers). Meshes come from
-- scenarios/meshes/, relative to this file.
local meshes = "meshes/"
return {
  duration = 1,
  objects = {
    { name = "box", shape = "box", size = {0.02, 0.04, 0.06}, density = 500, position = {0, 0, 1} },
    { name = "ball", shape = "sphere", radius = 0.02, density = 1000, position = {0.1, 0, 1} },
    { name = "can", shape = "cylinder", radius = 0.03, length = 0.1, mass = 0.3, position = {0.2, 0, 1} },
    { name = "pill", shape = "capsule", radius = 0.01, length = 0.04, density = 1100, position = {0.3, 0, 1} },
    { name = "gem", shape = "convex", file = meshes .. "octahedron.obj", density = 2000, position = {0.4, 0, 1} },
    { name = "ring", shape = "mesh", file = meshes .. "ring.obj", density = 800, position = {0.5, 0, 1},
      angular_velocity = {0, 0, 2} },
    { name = "wedge", shape = "convex", file = meshes .. "wedge_mm.stl", scale = 0.001, density = 700,
      position = {0.6, 0, 1}, orientation = {0.7071067811865476, 0, 0, 0.7071067811865476} },
  },
}
