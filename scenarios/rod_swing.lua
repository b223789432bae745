-- rod_swing: a rod held at one end and swung; its centre of gravity follows an arc about the grip
-- (Melder, Harwin & Sharkey, section 6: "if a long 'virtual' rod is grasped with two or three
-- fingers at one end and swung, the position of the centre of gravity of the rod will follow an
-- arc, (as long as there is no slip at the grasp points)").
--
-- A 30 cm, 0.5 kg rod (4 x 4 cm) hangs from thumb and index pinching it 3 cm below its top end,
-- 1.5 cm deep each side (k = 300 N/m: 4.5 N per finger, mu = 1). Two point contacts hold no
-- torque about the line through them (section 3.2; no torsion rule here), so the grip is a hinge
-- and the rod a pendulum hung from the hand: centre of mass r = 12 cm below the grip, J about
-- the grip 0.011 kg m^2, small swings at w = sqrt(m g r / J) = 7.3 rad/s. The hand swings it by
-- moving 1.5 cm back and forth along x at w from 0.3 s to about 2.3 s, then holds still while
-- the rod swings on. At the paper's 50 Hz physics the grip is stable: the mode of the rod on the
-- finger springs (m_eff = 0.17 kg at the grip, 2 k = 600 N/m) turns 1.2 rad per step, under 2.
-- Nothing slips: the fingers share the rod's pull along it, at most (at the bottom of a swing
-- of a = 35 degrees) m g (1 + (1 - cos a)(2 m r^2 / J)) = 6.4 N, 3.2 N each, while each
-- friction circle allows mu k d = 4.5 N.
-- So the centre of mass stays at a fixed distance from the hand but for the finger springs,
-- which stretch with the pull along the rod, T / (2 k); for a rod swinging to a about a pivot
-- (J about the grip, r grip to centre) T = m (g cos phi + r phi'^2) changes between the bottom
-- and the turning points by m g (1 - cos a)(1 + 2 m r^2 / J). It pulls at twice the swing's
-- frequency on the springs' own mode along the rod (sqrt(2 k / m) = 35 rad/s), which amplifies
-- it by 1 / (1 - (2 w)^2 m / (2 k)) = 1.22. The check: while the hand holds still, the distance
-- from the hand to the centre of mass, sampled at every physics tick through the trajectory's
-- view, stays within a band of that change / (2 k) (r taken as the band's middle, since the
-- fingers catch the falling rod a few mm higher up than aimed), plus 10 % for what the bound
-- leaves out (the sideways stretch, second order; the grip's own ringing); and the rod has swung
-- between 15 and 35 degrees (beyond 35 the pull would near the friction limit).

local amplitude = param("amplitude", 0.015)   -- m: the hand's back-and-forth
local L, m = 0.30, 0.5                         -- m, kg
local top = 0.65                               -- m: the rod's top end
local grip = top - 0.03                        -- m: height of the fingers
local half_w, squeeze = 0.02, 0.015            -- m
local k = 300                                  -- N/m
local d = top - L / 2                          -- m: centre height (the rod hangs straight)
local r = grip - d                              -- m: grip to centre of mass
local J = m * (L * L + 4 * half_w * half_w) / 12 + m * r * r   -- kg m^2: about the grip
local w = math.sqrt(m * 9.81 * r / J)          -- rad/s

-- The hand's swing: on at 0.3 s, and held from the last turning point before 2.3 s (where its
-- speed is zero, so stopping does not jerk the grip springs).
local stop = 0.3 + (math.floor((2.0 * w - math.pi / 2) / math.pi) * math.pi + math.pi / 2) / w   -- s
local function hand_x(t)
  if t < 0.3 then return 0 end
  return amplitude * math.sin(w * (math.min(t, stop) - 0.3))
end

local settled = stop + 0.2   -- s: the grip springs' own ringing (59 rad/s, damping ratio 0.1:
                             -- m_eff = 0.17 kg at the grip, 2 k = 600 N/m, 2 c = 2 N s/m) has
                             -- died down by a factor e^-1.2 when the band starts
local band = { lo = math.huge, hi = -math.huge }   -- m: |centre - hand| while the hand holds
local widest = 0                                    -- degrees: the largest swing seen

local function swing_deg(rod) return math.deg(math.acos(math.min(1, rod.rotation[3][3]))) end

local function finger(side, watch)
  return function(t, sim)
    -- Outside at t = 0, pressed in from the first tick on: the rod falls 4 mm in the first
    -- physics step before the grip catches it.
    local y = side * (t == 0 and half_w + 0.002 or half_w - squeeze)
    if watch and sim ~= nil then
      local rod = sim.objects.rod
      widest = math.max(widest, swing_deg(rod))
      if sim.time > settled then
        -- The hand is where the fingers' HIPs are (midway between them): the script's hold, or
        -- a device's tip, which the rod's pull moves when the hand is soft.
        local a, b = sim.fingers.thumb.hip, sim.fingers.index.hip
        local hand = { (a[1] + b[1]) / 2, (a[2] + b[2]) / 2, (a[3] + b[3]) / 2 }
        local p = rod.position
        local r = math.sqrt((p[1] - hand[1]) ^ 2 + (p[2] - hand[2]) ^ 2 + (p[3] - hand[3]) ^ 2)
        band.lo, band.hi = math.min(band.lo, r), math.max(band.hi, r)
      end
    end
    return hand_x(t), y, grip
  end
end

local slip_before = {}

return {
  name = "rod_swing",
  description = "A rod pinched at one end is swung; its centre of mass follows an arc about the grip.",
  duration = 4.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  objects = {
    { name = "rod", size = { 2 * half_w, 2 * half_w, L }, mass = m, position = { 0, 0, d },
      material = { mu = 1.0 } },
  },
  fingers = {
    { name = "thumb", stiffness = k, damping = 1, trajectory = finger(-1, true) },
    { name = "index", stiffness = k, damping = 1, trajectory = finger(1, false) },
  },
  expect = {
    { what = "both fingers hold the rod before the swing", at = 0.3,
      check = function(sim)
        slip_before = { thumb = sim.fingers.thumb.slip, index = sim.fingers.index.slip }
        local t, i = sim.fingers.thumb.touching, sim.fingers.index.touching
        return t == "rod" and i == "rod", string.format("thumb on '%s', index on '%s'", t, i)
      end },
    { what = "the rod has swung between 15 and 35 degrees",
      check = function(sim) return widest >= 15 and widest <= 35, string.format("%.1f degrees", widest) end },
    { what = "the centre of mass keeps its distance from the still hand but for the finger springs' stretch (an arc)",
      check = function(sim)
        local a = math.rad(widest)
        local rm = (band.lo + band.hi) / 2                         -- m: hand to centre, measured
        local Jm = m * (L * L + 4 * half_w * half_w) / 12 + m * rm * rm
        local resonance = 1 / (1 - (2 * w) ^ 2 / (2 * k / m))     -- pull at 2 w on the 2 k / m spring
        local bound = 1.1 * resonance * m * 9.81 * (1 - math.cos(a)) * (1 + 2 * m * rm * rm / Jm) / (2 * k)
        return band.hi - band.lo < bound,
               string.format("%.1f to %.1f mm: band %.2f mm, bound %.2f mm for %.1f degrees",
                             band.lo * 1000, band.hi * 1000, (band.hi - band.lo) * 1000, bound * 1000, widest)
      end },
    { what = "neither finger slips during the swing (under 0.1 mm)",
      check = function(sim)
        local t, i = sim.fingers.thumb, sim.fingers.index
        local st, si = t.slip - slip_before.thumb, i.slip - slip_before.index
        return t.touching == "rod" and i.touching == "rod" and st < 1e-4 and si < 1e-4,
               string.format("thumb %.4f mm, index %.4f mm", st * 1000, si * 1000)
      end },
  },
}
