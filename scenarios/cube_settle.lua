-- cube_settle: the paper's "rotate down" object contact (Melder, Harwin & Sharkey, section 4).
--
-- A 10 cm, 0.5 kg cube is dropped corner first from 1 cm onto the floor (its body diagonal vertical,
-- tipped 5 degrees so that it does not balance on the corner). A penalty force along the floor's
-- normal, proportional to each penetrating vertex's depth, acts at that vertex: first one corner,
-- then two (an edge), then four (a face) carry it, and damping takes the energy away until it
-- rests face down. At the paper's 50 Hz the floor must be soft to be stable (the rocking mode
-- needs 12 k / m h^2 < 4 - 2 h 12 c / m), so the cube rests m g / (4 k) = 12 mm deep; try
-- --set rates.physics=500 --set stiffness=2000 --set damping=10 for a firm floor.

local mass = 0.5                                -- kg
local half = 0.05                               -- m
local k = param("stiffness", 100)               -- N/m per vertex
local c = param("damping", 1)                   -- N s/m per vertex
local tip = math.rad(param("tip", 5))           -- rad: off the balanced corner

-- Quaternion product and axis-angle, to write the orientation down.
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
-- Body diagonal vertical: 45 degrees about x, then atan(1/sqrt 2) about y; then the tip.
local corner_down = qmul(axis_angle(1, 2, 0, tip),
                         qmul(axis_angle(0, 1, 0, math.atan(1 / math.sqrt(2))), axis_angle(1, 0, 0, math.pi / 4)))

-- The largest |cosine| between world z and a body axis: 1 when a face is down.
local function face_alignment(q)
  local w, x, y, z = q[1], q[2], q[3], q[4]
  local zx, zy, zz = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
  return math.max(math.abs(zx), math.abs(zy), math.abs(zz))
end

return {
  name = "cube_settle",
  description = "A cube dropped corner first rotates down onto an edge, then a face.",
  duration = 5.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  floor = { material = { mu = 0.6, stiffness = k, damping = c } },
  objects = {
    { name = "cube", size = { 2 * half, 2 * half, 2 * half }, mass = mass,
      position = { 0, 0, half * math.sqrt(3) + 0.01 }, orientation = corner_down,
      material = { mu = 0.6 } },
  },
  expect = {
    { what = "the cube has landed on a face: four corners touch the floor",
      check = function(sim)
        local n = sim.objects.cube.floor_contacts
        return n == 4, string.format("%d corners", n)
      end },
    { what = "it rests face down within 0.1 degree",
      check = function(sim)
        local tilt = math.deg(math.acos(math.min(1, face_alignment(sim.objects.cube.orientation))))
        return tilt < 0.1, string.format("%.3f degrees", tilt)
      end },
    { what = "it is at rest",
      check = function(sim)
        local v = sim.objects.cube.velocity
        local speed = math.sqrt(v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2)
        return speed < 0.001, string.format("%.2g m/s", speed)
      end },
  },
}
