-- corner_drop: a cube dropped corner first onto a stiff penalty floor, a hard case of the benchmark
-- (tools/bench/cases.hpp, corner_drop; README.md, "Speed against error").
--
-- cube_settle's 10 cm, 0.5 kg cube, dropped corner first from 1 cm, onto a floor a thousand times
-- stiffer (100 kN/m per vertex, 20 N s/m) with physics at 1 kHz. The explicit (symplectic Euler)
-- step is stable for a contact mode while h^2 K / M < 4 - 2 h C / M; the benchmark's bisection puts
-- the largest stable stiffness for this drop at 2.8e5 N/m at 1 kHz (and 760 N/m at the paper's
-- 50 Hz), so 1e5 is stable: the cube lands, rotates down onto a face and rests m g / (4 k) = 12 um
-- deep. It keeps a period-2 tangential cycle: its centre alternates by 2.4 um between two points
-- every physics step (1.7 mm/s), the floor's friction anchors slipping in a friction circle only
-- mu m g / (4 k) = 7 um wide; no creep (engine/README.md, "Limits"). That
-- is the paper's step (--set integrator=paper); the implicit one, the default, rests the cube at
-- any stiffness. Try --set integrator=paper --set stiffness=3e6: the explicit step blows up, and
-- the energy watch (engine/energy.hpp) stops the run at the physics tick the cube's energy passes
-- its bound, naming the body, with exit 2 and the trace kept; --set rates.physics=50 too.

local mass = 0.5                                -- kg
local half = 0.05                               -- m
local k = param("stiffness", 1e5)               -- N/m per vertex
local c = param("damping", 20)                  -- N s/m per vertex
local tip = math.rad(5)                         -- rad: off the balanced corner

local function qmul(a, b)
  return { a[1] * b[1] - a[2] * b[2] - a[3] * b[3] - a[4] * b[4],
           a[1] * b[2] + a[2] * b[1] + a[3] * b[4] - a[4] * b[3],
           a[1] * b[3] - a[2] * b[4] + a[3] * b[1] + a[4] * b[2],
           a[1] * b[4] + a[2] * b[3] - a[3] * b[2] + a[4] * b[1] }
end
local function axis_angle(x, y, z, angle)
  local n = math.sqrt(x * x + y * y + z * z)
  local s = math.sin(angle / 2) / n
  return { math.cos(angle / 2), x * s, y * s, z * s }
end
local corner_down = qmul(axis_angle(1, 2, 0, tip),
                         qmul(axis_angle(0, 1, 0, math.atan(1 / math.sqrt(2))), axis_angle(1, 0, 0, math.pi / 4)))

local settled_at = nil   -- the centre at 1 s (set by the check due then)

local function face_alignment(R)
  return math.max(math.abs(R[3][1]), math.abs(R[3][2]), math.abs(R[3][3]))
end

return {
  name = "corner_drop",
  description = "A cube dropped corner first onto a stiff penalty floor lands, rotates down and rests.",
  duration = 2.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 1000 },
  gyroscopic = "implicit",
  floor = { material = { mu = 0.6, stiffness = k, damping = c } },
  objects = {
    { name = "cube", size = { 2 * half, 2 * half, 2 * half }, mass = mass,
      position = { 0, 0, half * math.sqrt(3) + 0.01 }, orientation = corner_down,
      material = { mu = 0.6 } },
  },
  expect = {
    { what = "it has not bounced above its release height",
      at = 0.3,
      check = function(sim)
        local z = sim.objects.cube.position[3]
        return z < sim.initial.objects.cube.position[3], string.format("centre at %.4f m", z)
      end },
    { what = "it rests on a face: four corners on the floor, level within 0.1 degree",
      check = function(sim)
        local n = sim.objects.cube.floor_contacts
        local tiltd = math.deg(math.acos(math.min(1, face_alignment(sim.objects.cube.rotation))))
        return n == 4 and tiltd < 0.1, string.format("%d corners, %.3f degrees", n, tiltd)
      end },
    { what = "by 1 s it has landed on a face", at = 1.0,
      check = function(sim)
        local o = sim.objects.cube
        settled_at = { o.position[1], o.position[2], o.position[3] }
        return o.floor_contacts == 4, string.format("%d corners", o.floor_contacts)
      end },
    { what = "it rests at the depth m g / (4 k) within 5%",
      check = function(sim)
        local depth = half - sim.objects.cube.position[3]
        local expected = mass * 9.81 / (4 * k)
        return math.abs(depth - expected) < 0.05 * expected,
               string.format("%.2f um (expected %.2f)", depth * 1e6, expected * 1e6)
      end },
    { what = "and does not creep: within 10 um of where it was at 1 s",
      check = function(sim)
        if not settled_at then return false, "no position at 1 s" end
        local p = sim.objects.cube.position
        local d = math.sqrt((p[1] - settled_at[1]) ^ 2 + (p[2] - settled_at[2]) ^ 2 + (p[3] - settled_at[3]) ^ 2)
        return d < 10e-6, string.format("moved %.2f um", d * 1e6)
      end },
  },
}
