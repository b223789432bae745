-- pole_balance: one finger balances a pole from below (Melder, Harwin & Sharkey, section 3.3:
-- "balance a long object so the god-object is kept below the centre of gravity in an unstable
-- position, such as might be used by an acrobat balancing a pole").
--
-- A 1 m, 0.5 kg pole (2 x 2 cm) stands on one finger pressed 16 mm into its bottom face
-- (k d = m g), leaning 3 degrees. Left alone it falls: a pole on a point that pushes no
-- sideways force tips over as e^(lambda t), lambda = sqrt(6 g / L) = 7.7 rad/s. The finger's
-- trajectory is a feedback controller: it reads the pole's lean, spin, position and velocity
-- from the view (the state the last physics tick left) and moves the HIP sideways under the
-- god-object by F / k, so the finger pushes the sideways force F = m u with
--   u = k1 theta + k2 omega + k3 x + k4 v   (per horizontal axis),
-- gains that put all four poles of the linearised pole-and-hand at s = -p (p = 5 rad/s):
--   theta'' = (6 / L)(g theta - u),  x'' = u
--   => s^4 + (a k2 - k4) s^3 + (a k1 - k3 - a g) s^2 + a g k4 s + a g k3 = (s + p)^4,  a = 6 / L.
-- Stick: |F| / (m g) = |u| / g stays far below mu = 1, so the god-object does not slip.
-- --set gain=0 switches the sideways force off (the HIP follows the god-object): the pole falls,
-- and "stays within 5 degrees of upright" fails (tests/e2e/test_feedback.cpp checks that).

local gain = param("gain", 1.0)          -- 1: the controller above; 0: no sideways force
local lean = param("lean", 3.0)          -- degrees: initial lean about y
local L, m, k = 1.0, 0.5, 300            -- m, kg, N/m
local g = 9.81
local d0 = m * g / k                     -- m: press depth that carries the weight (16 mm)
local base = { 0, 0, 0.2 }               -- m: bottom face centre at t = 0
local p = 5.0                            -- rad/s: the closed loop's poles
local a = 6 / L
local k3 = p ^ 4 / (a * g)
local k4 = 4 * p ^ 3 / (a * g)
local k2 = (4 * p + k4) / a
local k1 = (6 * p ^ 2 + k3 + a * g) / a

local c, s = math.cos(math.rad(lean) / 2), math.sin(math.rad(lean) / 2)
local axis0 = { math.sin(math.rad(lean)), 0, math.cos(math.rad(lean)) }   -- the pole's axis
local centre = { base[1] + L / 2 * axis0[1], base[2], base[3] + L / 2 * axis0[3] }

local worst = 0        -- degrees: the largest lean the controller saw (every physics tick)

local function tilt_deg(rotation) return math.deg(math.acos(math.min(1, rotation[3][3]))) end

-- The finger: 5 mm below the bottom face at t = 0 (the pole drops 3.9 mm in the first physics
-- step, before the finger carries it; its first move must enter the bottom face from outside), then
-- pressed d0 in, and moved sideways by the controller.
local function finger(t, sim)
  if t == 0 or sim == nil then return base[1], base[2], base[3] - 0.005 end
  local pole = sim.objects.pole
  local R, w, x, v = pole.rotation, pole.angular_velocity, pole.position, pole.velocity
  worst = math.max(worst, tilt_deg(R))
  -- lean toward +x is the axis' x component (rotation about +y); toward +y, its y (about -x)
  local ux = k1 * R[1][3] + k2 * w[2] + k3 * (x[1] - centre[1]) + k4 * v[1]
  local uy = k1 * R[2][3] - k2 * w[1] + k3 * (x[2] - centre[2]) + k4 * v[2]
  -- the god-object rides at the bottom face centre: position - L/2 axis; under the local model
  -- the finger feels the pole move on from the view at its velocities, so the centre is where
  -- the view puts it plus (t - sim.time) times the bottom's velocity, v + w x (-L/2 axis)
  local gx, gy = x[1] - L / 2 * R[1][3], x[2] - L / 2 * R[2][3]
  if sim.local_model then
    local age = t - sim.time
    gx = gx + age * (v[1] - L / 2 * (w[2] * R[3][3] - w[3] * R[2][3]))
    gy = gy + age * (v[2] - L / 2 * (w[3] * R[1][3] - w[1] * R[3][3]))
  end
  return gx + gain * m * ux / k, gy + gain * m * uy / k, base[3] + d0
end

return {
  name = "pole_balance",
  description = "One finger balances a 1 m pole upright from below by feedback.",
  duration = 4.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  objects = {
    { name = "pole", size = { 0.02, 0.02, L }, mass = m, position = centre,
      orientation = { c, 0, s, 0 }, material = { mu = 1.0 } },
  },
  fingers = {
    { name = "finger", stiffness = k, damping = 2, max_force = 10, trajectory = finger },
  },
  expect = {
    { what = "the pole stays within 5 degrees of upright for the whole run",
      check = function(sim)
        local now = tilt_deg(sim.objects.pole.rotation)
        worst = math.max(worst, now)
        return worst < 5, string.format("largest lean %.2f degrees (started at %.1f)", worst, lean)
      end },
    { what = "the pole is upright at the end (within 0.5 degrees)",
      check = function(sim)
        local now = tilt_deg(sim.objects.pole.rotation)
        return now < 0.5, string.format("%.3f degrees", now)
      end },
    { what = "the finger still carries the pole and has not slipped 1 mm",
      check = function(sim)
        local f = sim.fingers.finger
        return f.touching == "pole" and f.slip < 0.001,
               string.format("on '%s', slipped %.3f mm", f.touching, f.slip * 1000)
      end },
  },
}
