-- two_finger_lift: the paper's two-point grasp (Melder, Harwin & Sharkey, sections 2 and 3).
--
-- An 8 cm, 0.4 kg box rests on the floor. Thumb and index approach it from opposite sides,
-- squeeze it by 1 cm each, lift it 8 cm with a minimum-jerk motion and hold it.
--   grip per finger   N = k d = 400 N/m x 0.01 m = 4 N
--   needed            2 mu N > m g, i.e. N > m g / (2 mu) = 2.45 N   (margin 1.6)
--   hanging sag       m g / (2 k) = 4.9 mm of tangential spring stretch, inside the friction
--                     circle mu d = 8 mm, so the god-objects stick and nothing slips.
-- The finger damping (4 N s/m) lets the hanging box settle instead of bouncing on the finger
-- springs for ever (the paper's coupling is a pure spring: set it to 0 to see that).
--
-- The floor is the paper's penalty contact at the paper's 50 Hz physics rate. To be stable at
-- 50 Hz it must be soft: the box's rocking mode needs h^2 K / I < 4 - 2 h C / I, which at
-- h = 20 ms allows about 100 N/m per vertex for this box, so it rests m g / (4 k) = 9.8 mm
-- deep. The bound is on k / m, so the floor scales with the mass: --set mass=2 sinks the box
-- no deeper (and then the 4 N grip is too weak to lift it: 2 mu N < m g, and it slips).

local mass = param("mass", 0.4)            -- kg
local mu = param("mu", 0.8)                -- box and floor friction
local squeeze = param("squeeze", 0.01)     -- m: how far each finger presses into the box
local half = 0.04                          -- m: half the box's edge
local floor_k = 250 * mass                 -- N/m per vertex (100 for 0.4 kg)
local floor_c = 2.5 * mass                 -- N s/m per vertex (1 for 0.4 kg)
local rest = half - mass * 9.81 / (4 * floor_k)   -- m: box centre height at rest
local lift = 0.08                          -- m

-- side = -1 for the thumb (at -x), +1 for the index (at +x).
local function path(side)
  local outside, inside = side * 0.10, side * (half - squeeze)
  return {
    { t = 0.0, p = { outside, 0, rest } },
    { t = 1.0, p = { inside, 0, rest } },          -- approach and squeeze
    { t = 1.5, p = { inside, 0, rest } },          -- settle the grip
    { t = 3.0, p = { inside, 0, rest + lift } },   -- lift
  }                                                -- hold to the end
end

local function box(sim) return sim.objects.box end

return {
  name = "two_finger_lift",
  description = "Two fingers pinch a box on the floor, lift it 8 cm and hold it.",
  duration = 4.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  gravity = { 0, 0, -9.81 },
  floor = { height = 0, material = { mu = mu, stiffness = floor_k, damping = floor_c } },
  objects = {
    { name = "box", shape = "box", size = { 2 * half, 2 * half, 2 * half }, mass = mass,
      position = { 0, 0, rest }, material = { mu = mu } },
  },
  fingers = {
    { name = "thumb", stiffness = 400, damping = 4, max_force = 10, trajectory = path(-1) },
    { name = "index", stiffness = 400, damping = 4, max_force = 10, trajectory = path(1) },
  },
  expect = {
    { what = "both fingers grip the box before the lift", at = 1.5,
      check = function(sim)
        local t, i = sim.fingers.thumb.touching, sim.fingers.index.touching
        return t == "box" and i == "box", string.format("thumb on '%s', index on '%s'", t, i)
      end },
    { what = "the box is lifted at least 5 cm",
      check = function(sim)
        local rise = box(sim).position[3] - box(sim.initial).position[3]
        return rise >= 0.05, string.format("rose %.1f mm", rise * 1000)
      end },
    { what = "the box is held still at the end",
      check = function(sim)
        local v = box(sim).velocity
        local speed = math.sqrt(v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2)
        return speed < 0.001, string.format("speed %.2g m/s", speed)
      end },
    { what = "the thumb slips less than 2 mm",
      check = function(sim)
        return sim.fingers.thumb.slip < 0.002, string.format("%.3f mm", sim.fingers.thumb.slip * 1000)
      end },
    { what = "the index slips less than 2 mm",
      check = function(sim)
        return sim.fingers.index.slip < 0.002, string.format("%.3f mm", sim.fingers.index.slip * 1000)
      end },
  },
}
