-- gravity_drop: torsion about a two-finger grasp axis by gravity (Melder, Harwin & Sharkey,
-- section 3.2, solution 2).
--
-- A 20 x 4 x 4 cm rod of 0.2 kg is pinched across its width by thumb and index 8 cm from its
-- centre, held level. Two point contacts cannot resist a torque about the axis through them, so
-- the paper lets gravity turn the rod about that axis, with the torque scaled down by the
-- finger pads' torsional friction, [p x m g (1 - A/A_crit) . u] u, where A is the friction-circle
-- area (pi (mu d)^2 = 2.0e-4 m^2 for d = 8 mm) and A_crit the area at which the pads would hold
-- the rod level (here 2 A, so half the gravity torque acts). The rod swings down about the
-- axis like a pendulum with half gravity (small swings would take 2 pi sqrt(J_axis / (m g d /
-- 2)) = 1.0 s): released level, it passes the bottom after about 0.3 s and rises level on the
-- other side, and swings on, undamped, since the paper's torque has no torsional loss. The
-- fingers stick throughout. Try --set grasp.critical_area=1e-4 (below A: the pads hold the rod
-- level, and the first expectation fails) or --set rates.physics=500. With the pads' torsional
-- friction (grasp.torsional_damping) the turn is quasi-static instead: see dead_band.lua.

local squeeze = param("squeeze", 0.008)   -- m: how far each finger presses in
local half = { 0.10, 0.02, 0.02 }         -- m
local centre = { 0, 0, 0.3 }              -- m
local area = math.pi * (1.0 * squeeze) ^ 2   -- m^2: friction circle of each finger (mu = 1)

local function at_grip(side)              -- the HIP, fixed: 8 cm from the centre, inside the face
  return { { t = 0, p = { -0.08, side * (half[2] - squeeze), centre[3] } } }
end

-- Angle of the rod about the grasp axis (y), from its orientation quaternion {w, x, y, z}.
local function pitch(object) return 2 * math.atan(object.orientation[3], object.orientation[1]) end

return {
  name = "gravity_drop",
  description = "A rod pinched off-centre swings down about the axis through the two fingers.",
  duration = 3.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  grasp = { torsion = "gravity_drop", critical_area = 2 * area },
  objects = {
    { name = "rod", size = { 2 * half[1], 2 * half[2], 2 * half[3] }, mass = 0.2,
      position = centre, material = { mu = 1.0 } },
  },
  fingers = {
    { name = "thumb", stiffness = 400, damping = 2, trajectory = at_grip(-1) },
    { name = "index", stiffness = 400, damping = 2, trajectory = at_grip(1) },
  },
  expect = {
    { what = "the rod has swung down past 60 degrees about the grasp axis", at = 0.3,
      check = function(sim)
        local a = math.deg(pitch(sim.objects.rod))
        return a > 60, string.format("%.0f degrees", a)
      end },
    { what = "both fingers still hold the rod at the end",
      check = function(sim)
        local t, i = sim.fingers.thumb.touching, sim.fingers.index.touching
        return t == "rod" and i == "rod", string.format("thumb on '%s', index on '%s'", t, i)
      end },
    { what = "the grasp axis stays put: the rod's centre stays within 9 cm of it",
      check = function(sim)
        local p = sim.objects.rod.position
        local d = math.sqrt((p[1] + 0.08) ^ 2 + (p[3] - centre[3]) ^ 2)
        return d < 0.09, string.format("%.1f cm", d * 100)
      end },
  },
}
