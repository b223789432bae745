-- incline: static and kinetic friction on a plane tilted at theta (engine/README.md, "Choices").
--
-- The floor stays z = 0 and gravity is tilted instead: g = 9.81 (sin theta, 0, -cos theta) is a
-- plane tilted by theta = 25 degrees about y, downhill along +x. Two 8 x 8 x 4 cm, 0.4 kg boxes
-- rest on it, 20 cm apart:
--   'sticky'    mu_s = 0.6 > tan theta = 0.466: static friction holds it, it does not move;
--   'slippery'  mu_s = 0.4 < tan theta: it breaks away at once and slides with mu_k = 0.3, at
--               a = g (sin theta - mu_k cos theta) = 9.81 (0.42262 - 0.3 x 0.90631) = 1.4786 m/s^2.
-- The floor is soft enough for the paper's 50 Hz (k = 250 m per vertex, as in two_finger_lift);
-- friction takes the lower mu of the two materials, so the floor's mu is 1.
local theta = math.rad(param("theta_deg", 25))
local g = 9.81
local mass = 0.4
local floor_k, floor_c = 250 * mass, 2.5 * mass                  -- N/m, N s/m per vertex
local half = { 0.04, 0.04, 0.02 }
local rest = half[3] - mass * g * math.cos(theta) / (4 * floor_k)  -- m: centre height at rest
local mu_k = 0.3
local a = g * (math.sin(theta) - mu_k * math.cos(theta))          -- m/s^2 while sliding

return {
  name = "incline",
  description = "A box sticks on a 25 degree incline (tan theta < mu_s), another slides down it at g (sin theta - mu_k cos theta).",
  duration = 2.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  gravity = { g * math.sin(theta), 0, -g * math.cos(theta) },
  floor = { height = 0, material = { mu = 1, stiffness = floor_k, damping = floor_c } },
  objects = {
    { name = "sticky", shape = "box", size = { 0.08, 0.08, 0.04 }, mass = mass,
      position = { 0, -0.1, rest }, material = { mu = 0.6 } },
    { name = "slippery", shape = "box", size = { 0.08, 0.08, 0.04 }, mass = mass,
      position = { 0, 0.1, rest }, material = { mu = 0.4, mu_kinetic = mu_k } },
  },
  fingers = {},
  expect = {
    -- Static: the anchors' springs take up the downhill load m g sin theta / 4 per vertex, a
    -- stretch of 4.1 mm at k = 100 N/m. But the load arrives as a step at t = 0 on unstretched,
    -- lightly damped anchor springs: they overshoot towards twice that (8.3 mm), past the static
    -- circle mu_s f_n / k = 5.3 mm, so the box slips once by a few mm before it holds (a known
    -- artefact of penalty friction under step loads: engine/README.md, Limits). Bound: 15 mm,
    -- then at rest. Sliding at a = g (sin theta - mu_s cos theta) > 0 it would be 0.4 m by 2 s.
    { what = "the sticky box holds after its first settling slip (moves less than 15 mm)",
      check = function(sim)
        local p, p0 = sim.objects.sticky.position, sim.initial.objects.sticky.position
        local d = math.sqrt((p[1] - p0[1]) ^ 2 + (p[2] - p0[2]) ^ 2)
        return d < 0.015, string.format("moved %.2f mm", d * 1000)
      end },
    { what = "the sticky box is at rest at the end",
      check = function(sim)
        local v = sim.objects.sticky.velocity
        local s = math.sqrt(v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2)
        return s < 1e-4, string.format("%.2g m/s", s)
      end },
    -- Kinetic: v = a t once sliding. It breaks away within the first physics steps; the 2%
    -- allows that start (0.04 s of 2 s) and the discrete 50 Hz steps.
    { what = "the slippery box slides at g (sin theta - mu_k cos theta), within 2%",
      check = function(sim)
        local v = sim.objects.slippery.velocity[1]
        local expected = a * sim.time
        return math.abs(v / expected - 1) < 0.02,
          string.format("v = %.4f m/s, a t = %.4f m/s", v, expected)
      end },
    { what = "the slippery box stays on its base (it slides, it does not tip)",
      check = function(sim)
        return sim.objects.slippery.floor_contacts == 4, string.format("%d corners on the floor", sim.objects.slippery.floor_contacts)
      end },
  },
}
