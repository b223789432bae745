-- many_bodies: a scene as wide as a trace holds (recordings/README.md "Schema"), for the tests of
-- big traces: `objects` boxes of 10 cm and 1 kg apart on the floor (a square grid, 0.3 m between
-- centres: bench/scale_scenes.hpp's "apart" layout), resting, and `fingers` soft scripted
-- fingers, 25 over the top of each of the first boxes (a 5 x 5 grid 2 cm apart), each coming down
-- from 5 mm above it to 5 mm into it in 0.04 s and held there (0.2 N each). The floor is
-- two_finger_lift's, scaled to the mass; the boxes are stiff rather than rigid (in series with
-- the floor they leave it as it is), as two rigid objects would be a warning per pair.

local n = param("objects", 1000)
local nf = param("fingers", 0)
local side, mass, mu = 0.1, 1.0, 0.6
local floor_k, floor_c = 250 * mass, 2.5 * mass    -- N/m and N s/m per vertex
local rest = side / 2 - mass * 9.81 / (4 * floor_k)  -- m: centre height at rest
local columns = math.ceil(math.sqrt(n))
assert(nf <= 25 * n, "at most 25 fingers a box")

local objects = {}
for i = 0, n - 1 do
  local row, col = i // columns, i % columns
  objects[#objects + 1] = {
    name = "box" .. i, shape = "box", size = { side, side, side }, mass = mass,
    position = { (col - 0.5 * (columns - 1)) * 0.3, (row - 0.5 * (columns - 1)) * 0.3, rest },
    material = { mu = mu, stiffness = 1e6, damping = 1e4 },
  }
end

local fingers = {}
for j = 0, nf - 1 do
  local box, k = objects[j // 25 + 1], j % 25
  local x = box.position[1] + (k % 5 - 2) * 0.02
  local y = box.position[2] + (k // 5 - 2) * 0.02
  fingers[#fingers + 1] = {
    name = "f" .. j, stiffness = 40, damping = 0.4, max_force = 10,
    trajectory = { { t = 0, p = { x, y, rest + side / 2 + 0.005 } }, { t = 0.04, p = { x, y, rest + side / 2 - 0.005 } } },
  }
end

return {
  name = "many_bodies",
  description = "Boxes apart on the floor, fingers resting on the first of them.",
  duration = 0.1,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  gravity = { 0, 0, -9.81 },
  floor = { height = 0, material = { mu = mu, stiffness = floor_k, damping = floor_c } },
  objects = objects,
  fingers = fingers,
}
