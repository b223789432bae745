-- cube_on_beam: polygon-polygon contact by a clipped contact manifold (engine/README.md, "Shapes").
--
-- An 8 cm, 0.4 kg cube is set down across a 40 cm beam 4 cm wide lying on the floor. The cube's
-- corners overhang the beam on both sides and the beam's ends lie far outside the cube: no vertex
-- of either body ever enters the other, so a contact made of vertices (the paper's floor contact)
-- would let the cube fall through. The manifold clips the cube's bottom face against the beam's
-- top face and finds the four corners of their overlap (8 x 4 cm), each carrying k d, so the cube
-- rests m g / (4 k) = 4.9 mm into the beam, level.
-- At the paper's 50 Hz the contact must be soft: the pair's rocking needs h^2 12 k / mu_r below
-- 4 - 2 h 12 c / mu_r (mu_r the reduced mass, 0.37 kg), 2.6 < 3.0 here; and on a 4 cm rail the
-- four points' rocking stiffness 4 k (2 cm)^2 = 0.32 N m must beat the cube's weight's overturning
-- m g (4 cm) = 0.16 N m, so a narrower beam would need a stiffer contact and a faster physics loop
-- (tests/engine/test_object_contact.cpp does a 1 cm beam at 500 and 3000 Hz).

local k = 200                              -- N/m per contact point, cube on beam
local c = 0.8                              -- N s/m per contact point
local cube_mass, beam_mass = 0.4, 5.0      -- kg
local half = 0.04                          -- m: half the cube's edge
local beam_half = { 0.2, 0.02, 0.02 }      -- m
local floor_k, floor_c = 1250, 12.5        -- N/m, N s/m per beam vertex
local g = 9.81
local beam_z = beam_half[3] - (beam_mass + cube_mass) * g / (4 * floor_k)
local beam_top = beam_z + beam_half[3]
local depth = cube_mass * g / (4 * k)      -- m: expected overlap at rest

-- The largest |cosine| between world z and a body axis: 1 when a face is down.
local function face_alignment(q)
  local w, x, y, z = q[1], q[2], q[3], q[4]
  local zx, zy, zz = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
  return math.max(math.abs(zx), math.abs(zy), math.abs(zz))
end

return {
  name = "cube_on_beam",
  description = "A cube rests across a thin beam on the four points of a clipped contact manifold.",
  duration = 5.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  floor = { material = { mu = 1.0, stiffness = floor_k, damping = floor_c } },
  objects = {
    { name = "beam", size = { 2 * beam_half[1], 2 * beam_half[2], 2 * beam_half[3] }, mass = beam_mass,
      position = { 0, 0, beam_z }, material = { mu = 0.6 } },
    { name = "cube", size = { 2 * half, 2 * half, 2 * half }, mass = cube_mass,
      position = { 0, 0, beam_top + half + 0.002 },
      material = { mu = 0.6, stiffness = k, damping = c } },
  },
  expect = {
    { what = "the cube rests on the beam at m g / (4 k) deep (four manifold points)",
      check = function(sim)
        local overlap = (sim.objects.beam.position[3] + beam_half[3]) - (sim.objects.cube.position[3] - half)
        return math.abs(overlap - depth) < 0.01 * depth,
               string.format("%.3f mm, expected %.3f mm", overlap * 1000, depth * 1000)
      end },
    { what = "the cube is level within 0.1 degree",
      check = function(sim)
        local tilt = math.deg(math.acos(math.min(1, face_alignment(sim.objects.cube.orientation))))
        return tilt < 0.1, string.format("%.4f degrees", tilt)
      end },
    { what = "the cube never touches the floor",
      check = function(sim)
        return sim.objects.cube.floor_contacts == 0, string.format("%d corners", sim.objects.cube.floor_contacts)
      end },
    { what = "the cube is at rest",
      check = function(sim)
        local v = sim.objects.cube.velocity
        local speed = math.sqrt(v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2)
        return speed < 1e-4, string.format("%.2g m/s", speed)
      end },
  },
}
