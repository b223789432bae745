-- dead_band: the torque dead band stops the 50 Hz oscillation of a two-finger grasp (Melder,
-- Harwin & Sharkey, section 5).
--
-- The rod of gravity_drop.lua (20 x 4 x 4 cm, 0.2 kg, pinched across its width 8 cm from its
-- centre, A_crit = 2 A so half the gravity torque acts) is released level. Here the finger pads'
-- torsional friction c_t makes the turn about the grasp axis quasi-static (engine/README.md,
-- "Dead band"): each physics step turns the rod by h T / c_t, T = -K sin(theta) at theta from
-- hanging, K = m g d / 2 = 0.0785 N m/rad. The pads are chosen so that at the paper's 50 Hz a
-- step near the bottom turns the rod 1.98 times past it (h K / c_t = 1.98): it comes down,
-- then overshoots at every update and the torque reverses at the next one, ringing down only by
-- 2% a step. The dead band, |T| <= T_crit gives zero torque, stops it for good once it is inside
-- |theta| <= asin(T_crit / K) (0.0255 rad for 2 mN m). At faster physics the same pads creep down
-- without overshoot and stop at the edge of the band.
--
-- Try --set dead_band=0 (at 50 Hz the rod is still swinging at the end: "it has not moved since
-- 3 s" fails) or --set dead_band=0.008 (a wider band: it stops sooner, further from hanging).

local t_crit = param("dead_band", 0.002)   -- N m: the paper's T_crit
local squeeze = 0.008                      -- m: how far each finger presses in
local half = { 0.10, 0.02, 0.02 }          -- m
local centre = { 0, 0, 0.3 }               -- m
local mass = 0.2                           -- kg
local area = math.pi * (1.0 * squeeze) ^ 2 -- m^2: friction circle of each finger (mu = 1)
local K = mass * 9.81 * 0.08 * 0.5         -- N m/rad: restoring torque per rad near hanging
local c_t = K / 50 / 1.98                  -- N m s/rad: overshoot 1.98 at the paper's 50 Hz
local band = math.asin(math.min(1, t_crit / K))   -- rad: |theta| inside which T = 0

local function at_grip(side)               -- the HIP, fixed: 8 cm from the centre, inside the face
  return { { t = 0, p = { -0.08, side * (half[2] - squeeze), centre[3] } } }
end

-- Angle of the rod from hanging straight down, about the grasp axis (y), from its orientation
-- quaternion {w, x, y, z} (level is -pi/2).
local function from_hanging(object)
  return 2 * math.atan(object.orientation[3], object.orientation[1]) - math.pi / 2
end

local at_3s = nil   -- the rod's orientation at 3 s, kept by the check at 3 s

return {
  name = "dead_band",
  description = "A rod pinched off-centre comes down about the grasp axis; the dead band stops its 50 Hz oscillation.",
  duration = 4.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  grasp = { torsion = "gravity_drop", critical_area = 2 * area, torsional_damping = c_t,
            dead_band = t_crit },
  objects = {
    { name = "rod", size = { 2 * half[1], 2 * half[2], 2 * half[3] }, mass = mass,
      position = centre, material = { mu = 1.0 } },
  },
  fingers = {
    { name = "thumb", stiffness = 400, damping = 2, trajectory = at_grip(-1) },
    { name = "index", stiffness = 400, damping = 2, trajectory = at_grip(1) },
  },
  expect = {
    { what = "the rod has come down near hanging by 1 s", at = 1.0,
      check = function(sim)
        local a = from_hanging(sim.objects.rod)
        return math.abs(a) < 0.2, string.format("%.3f rad from hanging", a)
      end },
    { what = "at 3 s the rod rests inside the dead band", at = 3.0,
      check = function(sim)
        at_3s = sim.objects.rod.orientation
        local a = from_hanging(sim.objects.rod)
        return math.abs(a) <= band, string.format("%.4f rad from hanging, band %.4f rad", a, band)
      end },
    { what = "it has not moved since 3 s",
      check = function(sim)
        local q = sim.objects.rod.orientation
        local same = at_3s ~= nil and q[1] == at_3s[1] and q[2] == at_3s[2] and q[3] == at_3s[3]
                     and q[4] == at_3s[4]
        return same, string.format("%.3g rad from hanging now", from_hanging(sim.objects.rod))
      end },
    { what = "both fingers still hold the rod at the end",
      check = function(sim)
        local t, i = sim.fingers.thumb.touching, sim.fingers.index.touching
        return t == "rod" and i == "rod", string.format("thumb on '%s', index on '%s'", t, i)
      end },
  },
}
