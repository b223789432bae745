-- gimbal_twist: turning a pinched box about the grasp axis with an instrumented gimbal
-- (Melder, Harwin & Sharkey, section 3.2, solution 1).
--
-- Two point contacts cannot turn a body about the line through them; the paper reads the pitch
-- of one finger's gimbal and, once the friction-circle area A exceeds A_crit, turns the body by
-- the pitch change about that line. Thumb (the gimbal finger, at -x) and index (at +x) pinch a
-- 6 cm, 0.2 kg box 1 cm deep (A = pi (mu d)^2 = 3.1e-4 m^2 with mu = 1, three times
-- A_crit = 1e-4 m^2), hold it in the air, and the thumb's scripted pitch turns from 0 to 90
-- degrees (minimum jerk, 1.0 s to 2.5 s). The axis u runs from the thumb to the index (+x), so
-- the box must turn +90 degrees about +x, half of it by t = 1.75 s, and nowhere else.
--   grip 4 N per finger vs m g / (2 mu) = 0.98 N needed: the pinch holds with margin 4.
-- Tolerances: the engine turns the box by the pitch change at each physics step, so a check
-- between steps sees the box as the last step left it: behind the pitch by up to one physics
-- period at the pitch rate, at most 1.875 x 90 / 1.5 = 112.5 deg/s x 0.02 s = 2.25 degrees
-- (at 50 Hz; measured 1.125 at the midpoint, 0.01 s after a step). At rest the only error is what
-- the residual torque turns about u, which the hinge stops: 0.5 degrees. The grasp axis is the
-- line through the two god-objects, which stick to the box: if the twist turned the box about
-- any other line, that line would leave the hands' (HIP to HIP), stretching the fingers' springs
-- sideways; it may lean off the hands' line by what the hanging sag allows: 2 degrees. (Measured
-- against the hands, not the world's x: a hand that is not where the script puts it, jittered or
-- a simulated Phantom lagging the closing grip, catches the box askew, and the axis is where the
-- hands hold it.) The fingers close in 0.05 s while the box falls (no floor): at 50 Hz they slip
-- 4.5 mm as the grip catches it, so the no-slip check counts only the slip from 1 s on, when the
-- twist starts.

local pitch = math.rad(param("pitch", 90))   -- rad: the thumb's final gimbal pitch
local half, squeeze = 0.03, 0.01             -- m
local z = 0.3                                -- m: the box's centre at t = 0

local function path(side, with_pitch)
  local outside, inside = side * (half + 0.002), side * (half - squeeze)
  local final = with_pitch and pitch or 0
  return {
    { t = 0.0, p = { outside, 0, z }, pitch = 0 },
    { t = 0.05, p = { inside, 0, z }, pitch = 0 },       -- grip at once: the box falls meanwhile
    { t = 1.0, p = { inside, 0, z }, pitch = 0 },        -- hang still
    { t = 2.5, p = { inside, 0, z }, pitch = final },    -- turn the gimbal
  }
end

-- The box's rotation as angle about x, and the tilt of its x axis off the world x axis.
local slip_before = {}                       -- m: each finger's slip at 1 s

local function about_x(box) return math.deg(2 * math.atan(box.orientation[2], box.orientation[1])) end

-- Degrees between the line from a to b and the line from c to d.
local function between_lines(a, b, c, d)
  local u = { b[1] - a[1], b[2] - a[2], b[3] - a[3] }
  local v = { d[1] - c[1], d[2] - c[2], d[3] - c[3] }
  local dot = u[1] * v[1] + u[2] * v[2] + u[3] * v[3]
  local norms = math.sqrt((u[1] ^ 2 + u[2] ^ 2 + u[3] ^ 2) * (v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2))
  return math.deg(math.acos(math.max(-1, math.min(1, dot / norms))))
end

return {
  name = "gimbal_twist",
  description = "The gimbal pitch of one finger turns a pinched box about the grasp axis.",
  duration = 3.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  grasp = { torsion = "gimbal", critical_area = 1e-4, gimbal_finger = "thumb" },
  objects = {
    { name = "box", size = { 2 * half, 2 * half, 2 * half }, mass = 0.2, position = { 0, 0, z },
      material = { mu = 1.0 } },
  },
  fingers = {
    { name = "thumb", stiffness = 400, damping = 4, trajectory = path(-1, true) },
    { name = "index", stiffness = 400, damping = 4, trajectory = path(1, false) },
  },
  expect = {
    { what = "the box has not turned about the grasp axis before the gimbal moves", at = 1.0,
      check = function(sim)
        slip_before = { thumb = sim.fingers.thumb.slip, index = sim.fingers.index.slip }
        local a = about_x(sim.objects.box)
        return math.abs(a) < 0.5, string.format("%.3f degrees", a)
      end },
    { what = "halfway through the pitch change the box has turned half of it (within one " ..
             "physics period of the pitch rate)",
      at = 1.75,
      check = function(sim)
        local a, want = about_x(sim.objects.box), math.deg(pitch) / 2
        local allowance = 1.875 * math.abs(math.deg(pitch)) / 1.5 * 0.02
        return math.abs(a - want) < allowance,
               string.format("%.3f degrees for a pitch of %.1f (allowance %.2f)", a, want, allowance)
      end },
    { what = "the box has turned by the pitch change about the grasp axis (within 0.5 degrees)",
      check = function(sim)
        local a, want = about_x(sim.objects.box), math.deg(pitch)
        return math.abs(a - want) < 0.5, string.format("%.3f degrees for a pitch of %.1f", a, want)
      end },
    { what = "the grasp axis stays put: the line through the god-objects stays within 2 degrees " ..
             "of the line between the hands",
      check = function(sim)
        local t, i = sim.fingers.thumb, sim.fingers.index
        local a = between_lines(t.god_object, i.god_object, t.hip, i.hip)
        return a < 2, string.format("%.2f degrees", a)
      end },
    { what = "both fingers still hold the box and slip less than 0.1 mm during the twist",
      check = function(sim)
        local t, i = sim.fingers.thumb, sim.fingers.index
        local st, si = t.slip - slip_before.thumb, i.slip - slip_before.index
        return t.touching == "box" and i.touching == "box" and st < 1e-4 and si < 1e-4,
               string.format("thumb on '%s' (%.4f mm), index on '%s' (%.4f mm)", t.touching,
                             st * 1000, i.touching, si * 1000)
      end },
  },
}
