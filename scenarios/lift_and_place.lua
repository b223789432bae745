-- lift_and_place: pick a box up from the floor, set it on another box, let go.
--
-- An 8 cm, 0.4 kg box stands on the floor; 25 cm away stands a 12 x 12 x 8 cm, 0.4 kg base. Thumb
-- and index pinch the box from its sides (along y), lift it 12 cm, carry it over the base, 1 cm
-- off its centre (--set offset=...), lower it to the height at which it rests there (so the base
-- takes its weight from the fingers before they open), open and withdraw. Nothing tells the
-- engine it is stacked: the box rests on the four points of the manifold of its bottom face on
-- the base's top face, m g / (4 k) deep, still, and level but for the small lean its off-centre
-- weight gives the whole stack on its springs (derived below, at the check).
--   grip per finger   N = k d = 400 N/m x 0.012 m = 4.8 N > m g / (2 mu) = 2.45 N   (margin 2.0)
--   hanging sag       m g / (2 k) = 4.9 mm of tangential stretch < mu d = 9.6 mm: no slip
-- The box is rigid (the fingers feel their own 400 N/m); the base's material is the softness of
-- both the box-base contact and, in series with the floor's, the base-floor contact.
--
-- Physics at 500 Hz, not the paper's 50 Hz. A pair rocks stably only for h^2 12 k / mu_r <
-- 4 - 2 h 12 c / mu_r (engine/README.md), mu_r the reduced mass, 0.2 kg here. At 50 Hz that caps
-- the base's k near 100 N/m per point: the box sinks m g / (4 k) = 9.8 mm into it, and the base,
-- whose floor contact has its material in series (k_bf <= k), sinks (m + M) g / (4 k_bf), 29 mm
-- with the draft's floor: a third of its height. The stack then barely stands: its rocking
-- stiffness on the floor, 4 k_bf a^2 = 0.96 N m/rad, is not twice gravity's overturning
-- g (M + 2 m) H = 0.47 N m/rad, so the box set 1 cm off centre leans the stack about 10 degrees
-- and it rocks on, under-damped (c <= 0.67 N s/m by the same bound): measured at 50 Hz, 24 mm off
-- centre and 11.6 degrees after 4 s, still moving at 2 cm/s (the same at 3000 Hz; set centred, the
-- stack's bounce has a damping ratio of at most 0.09). At 500 Hz (h = 2 ms) the bound is 100 times
-- looser:
--   box on base     k = 2000 N/m, c = 10 N s/m per point: h^2 12 k / mu_r = 0.48,
--                   2 h 12 c / mu_r = 2.4 (sum 2.9 < 4); rests m g / (4 k) = 0.49 mm deep
--   base on floor   k_bf = 1000 N/m, c_bf = 6.7 N s/m (2000 and 20 in series with the base's):
--                   rests (m + M) g / (4 k_bf) = 2.0 mm deep; rocking stiffness 14.4 N m/rad
--                   against 0.47 of overturning: a 1 cm offset leans the stack 0.165 degrees.
-- Every loop at 3000 Hz (tests/e2e/test_scenarios.cpp) runs the same materials, further inside
-- the bound. At --set rates.physics=50 these materials are flagged unstable and diverge.

local mass, base_mass = 0.4, 0.4           -- kg
local mu = 0.8
local half = 0.04                          -- m: half the box's edge
local base_half = { 0.06, 0.06, 0.04 }     -- m
local k, c = 2000, 10                      -- N/m, N s/m per point: the base's material
local floor_k, floor_c = 2000, 20          -- N/m, N s/m per vertex
local finger_k = 400                       -- N/m
local g = 9.81
local squeeze = 0.012                      -- m
local x0, x1 = -0.15, 0.10                 -- m: the box's start, the base's centre
local offset = param("offset", 0.01)       -- m: the box is set down this far off the base's centre, in x
local xp = x1 + offset                     -- m: where it is set down
local lift = 0.12                          -- m

local k_bf = k * floor_k / (k + floor_k)   -- N/m per vertex: base on floor, in series
local box_z = half - mass * g / (4 * floor_k)                  -- m: the rigid box on the floor
local base_z = base_half[3] - base_mass * g / (4 * k_bf)        -- m: the base alone, at t = 0
local depth = mass * g / (4 * k)                                -- m: the box's rest depth on the base
local base_loaded = base_half[3] - (mass + base_mass) * g / (4 * k_bf)
local box_rest = base_loaded + base_half[3] + half - depth      -- m: the box's centre at rest on the base
local base_top = base_z + base_half[3]

-- Waypoint times (s): grip, lift, carry, lower, hand over the weight, open, withdraw.
local t_grip, t_lift, t_carry, t_lower, t_hold, t_open, t_away = 0.8, 2.0, 3.3, 4.3, 4.8, 5.3, 5.8

-- side = -1 for the thumb (at -y), +1 for the index (at +y). The fingers' target height is the
-- box's centre: gripped on the floor with no stretch, they carry the same material points down
-- to box_rest, where the tangential stretch, and so the weight they hold, is back to zero.
local function path(side)
  local outside, inside = side * 0.10, side * (half - squeeze)
  return {
    { t = 0.0, p = { x0, outside, box_z } },
    { t = t_grip, p = { x0, inside, box_z } },              -- approach and squeeze
    { t = t_grip + 0.2, p = { x0, inside, box_z } },        -- settle the grip
    { t = t_lift, p = { x0, inside, box_z + lift } },       -- lift
    { t = t_carry, p = { xp, inside, box_z + lift } },      -- carry over the base
    { t = t_lower, p = { xp, inside, box_rest } },          -- lower onto it
    { t = t_hold, p = { xp, inside, box_rest } },           -- the base takes the weight
    { t = t_open, p = { xp, outside, box_rest } },          -- open
    { t = t_away, p = { xp, outside, box_rest + 0.05 } },   -- withdraw
  }
end

-- Angle (degrees) between world z and the nearest body axis: 0 when a face is down.
local function tilt(q)
  local w, x, y, z = q[1], q[2], q[3], q[4]
  local zx, zy, zz = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
  return math.deg(math.acos(math.min(1, math.max(math.abs(zx), math.abs(zy), math.abs(zz)))))
end

-- A body's z axis in world coordinates.
local function axis_z(o) return { o.rotation[1][3], o.rotation[2][3], o.rotation[3][3] } end

local slip_at_grip = {}

return {
  name = "lift_and_place",
  description = "Two fingers lift a box from the floor, place it on another box and let go; it rests there.",
  duration = 7.5,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 500 },
  floor = { material = { mu = mu, stiffness = floor_k, damping = floor_c } },
  objects = {
    { name = "box", size = { 2 * half, 2 * half, 2 * half }, mass = mass,
      position = { x0, 0, box_z }, material = { mu = mu } },
    { name = "base", size = { 2 * base_half[1], 2 * base_half[2], 2 * base_half[3] }, mass = base_mass,
      position = { x1, 0, base_z }, material = { mu = mu, stiffness = k, damping = c } },
  },
  fingers = {
    { name = "thumb", stiffness = finger_k, damping = 4, max_force = 10, trajectory = path(-1) },
    { name = "index", stiffness = finger_k, damping = 4, max_force = 10, trajectory = path(1) },
  },
  expect = {
    { what = "both fingers grip the box before the lift", at = t_grip + 0.2,
      check = function(sim)
        slip_at_grip = { thumb = sim.fingers.thumb.slip, index = sim.fingers.index.slip }
        local t, i = sim.fingers.thumb.touching, sim.fingers.index.touching
        return t == "box" and i == "box", string.format("thumb on '%s', index on '%s'", t, i)
      end },
    { what = "the box is carried over the base, clear of it", at = t_carry,
      check = function(sim)
        local p = sim.objects.box.position
        local clear = p[3] - half - base_top
        return math.abs(p[1] - xp) < 0.005 and clear > 0.02, string.format("x %.4f m, %.1f mm above", p[1], clear * 1000)
      end },
    -- A sticking finger's god-object stays on its material point (0 measured); 0.1 mm of slip,
    -- as in rod_swing, would be a fiftieth of the 4.9 mm sag that slipping would undo.
    { what = "the box did not slip in the grasp from the grip until the fingers open (under 0.1 mm)", at = t_hold,
      check = function(sim)
        local t, i = sim.fingers.thumb, sim.fingers.index
        local st, si = t.slip - slip_at_grip.thumb, i.slip - slip_at_grip.index
        return t.touching == "box" and i.touching == "box" and st < 1e-4 and si < 1e-4,
               string.format("thumb %.4f mm, index %.4f mm", st * 1000, si * 1000)
      end },
    { what = "the fingers have let go", at = t_away,
      check = function(sim)
        local t, i = sim.fingers.thumb.touching, sim.fingers.index.touching
        return t == "" and i == "", string.format("thumb on '%s', index on '%s'", t, i)
      end },
    -- At rest each of the four points carries m g / 4 = k d exactly: 2% of d (0.01 mm) allows
    -- the last of the settling motion and the base's own tilt, nothing more.
    { what = "the box rests on the base's top face, m g / (4 k) deep, within its footprint",
      check = function(sim)
        local b, s = sim.objects.box, sim.objects.base
        local n, u = axis_z(s), axis_z(b)
        -- Depth of the box's bottom-face centre under the base's top plane (the mean of its four
        -- points' depths), and its offset from the base's axis in that plane.
        local r = {}
        for i = 1, 3 do r[i] = (b.position[i] - half * u[i]) - (s.position[i] + base_half[3] * n[i]) end
        local overlap = -(r[1] * n[1] + r[2] * n[2] + r[3] * n[3])
        local off = math.sqrt((r[1] + overlap * n[1]) ^ 2 + (r[2] + overlap * n[2]) ^ 2 + (r[3] + overlap * n[3]) ^ 2)
        return off < base_half[1] - half and math.abs(overlap - depth) < 0.02 * depth,
               string.format("%.4f mm deep (expected %.4f), %.2f mm off the base's axis", overlap * 1000,
                             depth * 1000, off * 1000)
      end },
    -- Level but for the lean its off-centre weight gives the stack (small-angle statics): the
    -- base, on 4 k_bf a^2 of rocking stiffness about its bottom face less gravity's overturning
    -- g (M + 2 m) H (H its half height), and the box, on 4 k b^2 on the base less m g h2 (h2 its
    -- centre above the base's face), lean by psi = s m g e / (4 k_bf a^2 - g (M + 2 m) H - s m g h2),
    -- s = 1 / (1 - m g h2 / (4 k b^2)), e the box's offset: 0.165 degrees at e = 1 cm. Within 2%:
    -- the friction springs' stretch and the depths' second-order terms are below 0.1%; a box that
    -- rocked onto an edge or slid would be far off.
    { what = "the box is level but for the stack's lean under its off-centre weight (within 2%)",
      check = function(sim)
        local b, s = sim.objects.box, sim.objects.base
        local n = axis_z(s)
        local e = 0
        for i = 1, 2 do e = e + (b.position[i] - s.position[i] - (b.position[3] - s.position[3]) * n[i] / n[3]) ^ 2 end
        e = math.sqrt(e)
        local a, H, h2 = base_half[1], base_half[3], half - depth
        local sb = 1 / (1 - mass * g * h2 / (4 * k * half ^ 2))
        local lean = sb * mass * g * e / (4 * k_bf * a ^ 2 - g * (base_mass + 2 * mass) * H - sb * mass * g * h2)
        local expected, a_now = math.deg(lean), tilt(b.orientation)
        return math.abs(a_now - expected) <= 0.02 * expected + 1e-4,
               string.format("%.5f degrees (expected %.5f at %.2f mm off the base's axis)", a_now, expected, e * 1000)
      end },
    -- The slowest motion left is the stack rocking about its floor contact (v / w = 13 cm, the
    -- box's height), measured decaying at 4 /s: from 0.3 mm/s when the fingers have withdrawn
    -- (5.8 s), about 2e-7 m/s at 7.5 s. 1e-5 m/s (0.01 mm/s) leaves a factor 50 and fails a box
    -- that slides or rocks on (cm/s).
    { what = "the box is at rest (under 0.01 mm/s and 1e-3 rad/s)",
      check = function(sim)
        local v, w = sim.objects.box.velocity, sim.objects.box.angular_velocity
        local speed = math.sqrt(v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2)
        local spin = math.sqrt(w[1] ^ 2 + w[2] ^ 2 + w[3] ^ 2)
        return speed < 1e-5 and spin < 1e-3, string.format("%.2g m/s, %.2g rad/s", speed, spin)
      end },
  },
}
