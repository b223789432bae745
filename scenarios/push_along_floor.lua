-- push_along_floor: one-point contact (Melder, Harwin & Sharkey, section 3.3), pushing an object
-- along a surface.
--
-- One finger pushes an 8 cm, 0.4 kg box across the floor by its -x face, 1 cm below its centre
-- and `offset` to the side of it. The floor's friction (mu = 0.5, so about 2 N) resists at the
-- bottom vertices, the finger's force acts at its god-object on the face, and the residual force
-- and torque at the centre of mass move the box: pushed through the middle it slides straight;
-- pushed off-centre (--set offset=0.03) it also turns about the vertical, away from the finger.
-- The finger's friction (mu = 0.8) keeps its god-object from sliding over the face as it turns.

local offset = param("offset", 0.0)       -- m: push point, to the side (+y) of the face's centre
local mass, half = 0.4, 0.04              -- kg, m
local k_floor = 250 * mass                -- N/m per vertex, stable at 50 Hz (see two_finger_lift)
local rest = half - mass * 9.81 / (4 * k_floor)
local push_z = rest - 0.01                -- m: 1 cm below the centre, clear of the floor

-- Yaw of the box about z from its quaternion {w, x, y, z}.
local function yaw(q) return math.deg(math.atan(2 * (q[1] * q[4] + q[2] * q[3]), 1 - 2 * (q[3] ^ 2 + q[4] ^ 2))) end

return {
  name = "push_along_floor",
  description = "One finger pushes a box along the floor.",
  duration = 4.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  floor = { material = { mu = 0.5, stiffness = k_floor, damping = 2.5 * mass } },
  objects = {
    { name = "box", size = { 2 * half, 2 * half, 2 * half }, mass = mass, position = { 0, 0, rest },
      material = { mu = 0.8 } },
  },
  fingers = {
    { name = "index", stiffness = 400, damping = 4, max_force = 10,
      trajectory = {
        { t = 0.0, p = { -0.10, offset, push_z } },
        { t = 1.0, p = { -half + 0.008, offset, push_z } },   -- reach the face and press in
        { t = 3.5, p = { 0.10 - half + 0.008, offset, push_z } },   -- push 10 cm
      }, interpolation = "linear" },
  },
  expect = {
    { what = "the box slides at least 5 cm along x",
      check = function(sim)
        local dx = sim.objects.box.position[1] - sim.initial.objects.box.position[1]
        return dx > 0.05, string.format("%.1f mm", dx * 1000)
      end },
    { what = "it stays on its base: four corners on the floor at the end",
      check = function(sim)
        return sim.objects.box.floor_contacts == 4, string.format("%d corners", sim.objects.box.floor_contacts)
      end },
    { what = "pushed through the middle it does not turn (under 2 degrees); off-centre it turns away from the finger",
      check = function(sim)
        local a = yaw(sim.objects.box.orientation)
        if offset == 0 then return math.abs(a) < 2, string.format("%.2f degrees", a) end
        return a * offset < 0 and math.abs(a) > 2, string.format("%.1f degrees", a)
      end },
  },
}
