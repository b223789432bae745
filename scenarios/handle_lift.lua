-- handle_lift: one-point contact from below a handle (paper, section 3.3): an object lifted by a
-- finger hooked under its handle swings until its centre of gravity hangs below the god-object.
--
-- The handle is a steel ring (scenarios/meshes/ring.obj, a non-convex triangle mesh: a 12 mm
-- square section round a 16-gon of radius 30 mm), hung upright. One finger is inside the hole,
-- 12 mm to the side of the ring's centre line. Released at t = 0, the ring drops onto the
-- finger: the finger's path enters the inner surface of the ring's upper half, off to one side.
-- Gravity at the centre, the finger's force at the god-object: the residual torque turns the
-- ring until its centre hangs under the contact, the god-object walking over the inner facets as
-- the ring rolls on the finger. Then the finger lifts the ring 5 cm and holds it.
local mu = 0.8
local offset = param("offset", 0.012)      -- m: finger to the side of the ring's centre line
local k, c = 400, param("damping", 3)       -- N/m, N s/m: the finger coupling
local lift = 0.05                          -- m
-- The ring's axis (file z) along world y: turned +90 degrees about x (file y becomes world z).
local q = { math.cos(math.pi / 4), math.sin(math.pi / 4), 0, 0 }
local finger_z = 0.015                     -- m: the HIP, inside the hole above the centre

return {
  name = "handle_lift",
  description = "A ring hung on one finger swings until its centre hangs below the contact, then is lifted.",
  duration = 5.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  objects = {
    { name = "ring", shape = "mesh", file = "meshes/ring.obj", density = 7800,
      position = { 0, 0, 0 }, orientation = q, material = { mu = mu } },
  },
  fingers = {
    { name = "finger", stiffness = k, damping = c, max_force = 10,
      trajectory = { { t = 0, p = { offset, 0, finger_z } }, { t = 3, p = { offset, 0, finger_z } },
                     { t = 4, p = { offset, 0, finger_z + lift } } } },
  },
  expect = {
    { what = "the ring hangs on the finger before the lift", at = 2.9,
      check = function(sim)
        return sim.fingers.finger.touching == "ring", "touching '" .. sim.fingers.finger.touching .. "'"
      end },
    -- Pendulum about the contact: released with its centre 12 mm to the side of the finger, the
    -- ring swings about the vertical through the god-object with about that amplitude and, with
    -- no loss at a sticking pivot, keeps swinging (period 2 pi sqrt((J + m d^2) / (m g d)) =
    -- 0.51 s for d = 21 mm). Its centre stays below the god-object, within the amplitude plus
    -- 4 mm of the vertical through it, on both sides.
    { what = "the ring's centre hangs below the god-object, swinging about the vertical through it", at = 2.9,
      check = function(sim)
        local ring, go = sim.objects.ring.position, sim.fingers.finger.god_object
        local side, below = ring[1] - go[1], go[3] - ring[3]
        return below > 0.015 and math.abs(side) < offset + 0.004,
          string.format("%.1f mm below, %.1f mm to the side", below * 1000, side * 1000)
      end },
    -- Lifted: the HIP ends at 15 + 50 = 65 mm; the god-object hangs m g / k = 5.2 mm below it
    -- (m = 0.21 kg) and the centre about 21 mm below the god-object (the inner facets' distance
    -- from the centre at the contact), so the centre ends near 39 mm, up to 4 mm higher at the
    -- ends of its swing: between 33 and 45 mm.
    { what = "the finger lifts the ring: its centre ends 33 to 45 mm above its release point",
      check = function(sim)
        local z = sim.objects.ring.position[3] - sim.initial.objects.ring.position[3]
        return z > 0.033 and z < 0.045, string.format("%.1f mm", z * 1000)
      end },
    { what = "the finger never slips on the ring",
      check = function(sim)
        return sim.fingers.finger.slip < 0.001, string.format("%.3f mm", sim.fingers.finger.slip * 1000)
      end },
  },
}
