-- stack_lift: a stack carried with no special code.
--
-- A flat 8 x 8 x 2 cm, 0.1 kg box rests on an 8 cm, 0.4 kg box on the floor. Thumb and index
-- pinch the lower box, lift it 6 cm with a minimum-jerk motion and hold it. Nothing tells the
-- engine that the upper box is carried: it rides on the manifold of its contact with the lower
-- one (four points), whose friction anchors stick, so it rises with it without sliding.
--   grip per finger   N = k d = 400 N/m x 0.012 m = 4.8 N
--   needed            2 mu N > (m_low + m_up) g, N > 0.49 x 9.81 / 1.6 = 3.1 N   (margin 1.6)
--   lift acceleration below 0.6 m/s^2, so the upper box's inertia asks mu_s 0.06 of its friction.
-- At the paper's 50 Hz the contacts are soft: the upper box on the lower, k = 40 N/m per point,
-- h^2 12 k / mu_r = 2.4 < 4 - 2 h 12 c / mu_r = 3.4 (mu_r = 0.08 kg, the pair's reduced mass); it
-- rests m g / (4 k) = 6.1 mm into the lower box. The floor scales with the load (two_finger_lift).

local low_mass, up_mass = 0.4, 0.1          -- kg
local mu = 0.8
local squeeze = 0.012                       -- m
local half = 0.04                           -- m: half the lower box's edge
local up_half = { 0.04, 0.04, 0.01 }        -- m
local k_pair, c_pair = 40, 0.1              -- N/m, N s/m per point, upper on lower
local g = 9.81
local floor_k = 250 * (low_mass + up_mass)  -- N/m per vertex
local floor_c = floor_k / 100
local low_rest = half - (low_mass + up_mass) * g / (4 * floor_k)
local pair_depth = up_mass * g / (4 * k_pair)
local up_rest = low_rest + half + up_half[3] - pair_depth
local lift = 0.06                           -- m

local function path(side)
  local outside, inside = side * 0.10, side * (half - squeeze)
  return {
    { t = 0.0, p = { outside, 0, low_rest } },
    { t = 1.0, p = { inside, 0, low_rest } },          -- approach and squeeze
    { t = 1.5, p = { inside, 0, low_rest } },          -- settle the grip
    { t = 3.5, p = { inside, 0, low_rest + lift } },   -- lift
  }                                                    -- hold to the end
end

-- Upper box's centre relative to the lower box's, now and at t = 0.
local function offset(s)
  local a, b = s.objects.upper.position, s.objects.lower.position
  return { a[1] - b[1], a[2] - b[2], a[3] - b[3] }
end

return {
  name = "stack_lift",
  description = "Two fingers lift the lower box of a stack; the upper box rides along.",
  duration = 6.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  floor = { material = { mu = mu, stiffness = floor_k, damping = floor_c } },
  objects = {
    { name = "lower", size = { 2 * half, 2 * half, 2 * half }, mass = low_mass,
      position = { 0, 0, low_rest }, material = { mu = mu } },
    { name = "upper", size = { 2 * up_half[1], 2 * up_half[2], 2 * up_half[3] }, mass = up_mass,
      position = { 0, 0, up_rest }, material = { mu = mu, stiffness = k_pair, damping = c_pair } },
  },
  fingers = {
    { name = "thumb", stiffness = 400, damping = 4, max_force = 10, trajectory = path(-1) },
    { name = "index", stiffness = 400, damping = 4, max_force = 10, trajectory = path(1) },
  },
  expect = {
    { what = "both fingers grip the lower box before the lift", at = 1.5,
      check = function(sim)
        local t, i = sim.fingers.thumb.touching, sim.fingers.index.touching
        return t == "lower" and i == "lower", string.format("thumb on '%s', index on '%s'", t, i)
      end },
    { what = "the lower box is lifted at least 4 cm off the floor",
      check = function(sim)
        local rise = sim.objects.lower.position[3] - sim.initial.objects.lower.position[3]
        return rise >= 0.04 and sim.objects.lower.floor_contacts == 0, string.format("rose %.1f mm", rise * 1000)
      end },
    { what = "the upper box rode along: it moved less than 1 mm over the lower one",
      check = function(sim)
        local now, before = offset(sim), offset(sim.initial)
        local d = math.sqrt((now[1] - before[1]) ^ 2 + (now[2] - before[2]) ^ 2 + (now[3] - before[3]) ^ 2)
        return d < 0.001, string.format("%.3f mm", d * 1000)
      end },
    { what = "the upper box never touched the floor",
      check = function(sim)
        return sim.objects.upper.floor_contacts == 0, string.format("%d corners", sim.objects.upper.floor_contacts)
      end },
    { what = "the stack is held still at the end",
      check = function(sim)
        local v = sim.objects.upper.velocity
        local speed = math.sqrt(v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2)
        return speed < 0.001, string.format("upper box %.2g m/s", speed)
      end },
  },
}
