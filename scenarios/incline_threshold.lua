-- incline_threshold: two boxes on one incline, 2% either side of Coulomb's threshold tan(theta) = mu
-- (engine/README.md, "Hard cases"; the hard variant of incline.lua).
--
-- The floor stays z = 0 and gravity is tilted by theta = 25 degrees about y (downhill +x). Two
-- flat 12 x 12 x 4 cm, 0.4 kg boxes, each with mu_k = mu_s (no static peak):
--   'holds'   mu = tan(theta) / 0.98 = 0.476: it moves only by its anchors' stretch and stays;
--   'slides'  mu = tan(theta) / 1.02 = 0.457: it slides at a = g (sin - mu cos) = 0.081 m/s^2.
-- The load comes on as a step at t = 0, and the floor's friction force overshoots it by the box's
-- peak deceleration while the anchors take it up: a lightly damped anchor (incline.lua) swings to
-- twice its stretch and a box 2% under the threshold slides centimetres before it catches
-- (tests/engine/test_hard_cases.cpp measures 5.5 cm at 50 Hz). So the anchors here are overdamped,
-- c = 20 N s/m per vertex: the force overshoot, m K / C^2 = 0.4 x 400 / 80^2 = 2.5% by a first-
-- order estimate, measures under 2% (0.98 mu holds; at 0.99 mu the same box slides 4 mm before it
-- catches: the limit). The paper's 50 Hz cannot integrate such damping (the rocking mode's
-- 2 h 12 c / m = 24 > 4), so the physics runs at 500 Hz.
local theta = math.rad(25)
local g = 9.81
local mass = 0.4
local k, c = 100, 20                                   -- N/m, N s/m per vertex (floor)
local half = { 0.06, 0.06, 0.02 }
local rest = half[3] - mass * g * math.cos(theta) / (4 * k)   -- m: centre height at rest
local mu_hold = math.tan(theta) / 0.98
local mu_slide = math.tan(theta) / 1.02
local a = g * (math.sin(theta) - mu_slide * math.cos(theta))  -- m/s^2
-- The downhill vertices carry N_d = m g cos / 4 + F h_z / (4 h_x) (the friction at the base tilts
-- the load onto them); the box holds while they stick, so its base moves at most mu N_d / k.
local n_down = mass * g * math.cos(theta) / 4 + mass * g * math.sin(theta) * half[3] / (4 * half[1])
local stretch = mu_hold * n_down / k                   -- m

local function base_x(o)   -- the base centre's downhill position: centre less h_z along the body z
  return o.position[1] - half[3] * o.rotation[1][3]
end

local v_at_2 = nil
local held_at_2 = nil

return {
  name = "incline_threshold",
  description = "On a 25 degree incline a box with tan(theta) = 0.98 mu holds, one with 1.02 mu slides at g (sin - mu cos).",
  duration = 3.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 500 },
  gravity = { g * math.sin(theta), 0, -g * math.cos(theta) },
  floor = { height = 0, material = { mu = 1, stiffness = k, damping = c } },
  objects = {
    { name = "holds", shape = "box", size = { 0.12, 0.12, 0.04 }, mass = mass,
      position = { 0, -0.15, rest }, material = { mu = mu_hold } },
    { name = "slides", shape = "box", size = { 0.12, 0.12, 0.04 }, mass = mass,
      position = { 0, 0.15, rest }, material = { mu = mu_slide } },
  },
  fingers = {},
  expect = {
    { what = "at 2 s the box 2% under the threshold has moved no more than its anchors' stretch", at = 2.0,
      check = function(sim)
        held_at_2 = base_x(sim.objects.holds)
        v_at_2 = sim.objects.slides.velocity[1]
        return held_at_2 >= 0 and held_at_2 <= stretch,
          string.format("base moved %.3f mm, bound mu N_d / k = %.3f mm", held_at_2 * 1000, stretch * 1000)
      end },
    { what = "it stays: under 1 um more by 3 s, at rest",
      check = function(sim)
        local o = sim.objects.holds
        local d = base_x(o) - held_at_2
        local v = math.sqrt(o.velocity[1] ^ 2 + o.velocity[2] ^ 2 + o.velocity[3] ^ 2)
        return math.abs(d) < 1e-6 and v < 1e-6, string.format("moved %.2g m, %.2g m/s", d, v)
      end },
    -- Sliding, every vertex is on its friction circle: the floor's force is mu times its normal
    -- force. Over 2 s to 3 s, within 1e-3 (the residual rocking).
    { what = "the box 2% over the threshold slides at g (sin theta - mu cos theta), within 0.1%",
      check = function(sim)
        local dv = sim.objects.slides.velocity[1] - v_at_2
        return math.abs(dv / a - 1) < 1e-3, string.format("a = %.5f m/s^2, expected %.5f", dv, a)
      end },
  },
}
