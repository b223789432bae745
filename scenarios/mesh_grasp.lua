-- mesh_grasp: the two-point grasp of section 3.2 on an object read from a mesh file.
--
-- A wedge (a right triangular prism, read from scenarios/meshes/wedge_mm.stl, a binary STL in
-- millimetres, scaled x2: legs 80 and 60 mm, 40 mm thick) stands on its 80 x 40 mm face. Its
-- mass and inertia come from the mesh and the density (aluminium): volume 1/2 x 80 x 60 x 40 mm^3
-- = 96 cm^3, m = 0.259 kg; the loader moves the body to the mesh's centre of mass and principal
-- axes. Thumb and index pinch it across its thickness, on its two triangular faces (parallel:
-- the grasp axis is their common normal), lift it 6 cm, turn it 30 degrees about the vertical
-- while holding it, and hold it still.
--   grip per finger   N = k d = 400 N/m x 0.008 m = 3.2 N
--   needed            2 mu N > m g, i.e. N > m g / (2 mu) = 1.59 N   (margin 2.0)
-- The contacts run on the mesh's faces: entry through the triangle the finger's path crossed,
-- the god-object walked over the face (here one planar face made of one triangle per side).
--
-- Two point contacts cannot resist a torque about the line through them: a wedge whose centre
-- of mass sits even 1 mm off that line swings about it like a pendulum for ever (run with
-- --set locked=0 to see a 50 degree swing). The paper's answer (section 3.2) is the friction-
-- circle area: above A_crit the grasp holds the object against turning about the axis. Here
-- r = mu d = 0.8 x 8 mm = 6.4 mm, A = pi r^2 = 1.29e-4 m^2 > A_crit = 1e-4 m^2: locked.
--
-- As in two_finger_lift the floor must be soft at the paper's 50 Hz: k = 250 m per vertex keeps
-- the rocking mode stable (h^2 12 k / m = 1.2 < 4 - 2 h 12 c / m); the wedge rests on its four
-- base corners m g / (4 k) = 9.8 mm deep.

local mu = 0.8
local density = 2700                       -- kg/m^3
local scale = 0.002                        -- m per file unit (the file is in mm; x2)
local mass = density * 0.5 * 0.08 * 0.06 * 0.04   -- kg, for the floor's stiffness only
local floor_k, floor_c = 250 * mass, 2.5 * mass   -- N/m, N s/m per vertex
local sink = mass * 9.81 / (4 * floor_k)   -- m
local thick = 0.04                         -- m: the wedge's thickness (file z x scale)
local squeeze = param("squeeze", 0.008)    -- m
local lift, turn = 0.06, math.rad(30)
local locked = param("locked", 1)          -- 1: the grasp resists turning about its axis (A > A_crit)
-- The file's frame: triangle (0,0), (40,0), (0,30) mm in its xy plane, thickness along z.
-- Turned +90 degrees about x, file y becomes world z (the triangle stands up) and file z becomes
-- world -y: the wedge spans world y in [-thick, 0] about its position, which we put at
-- y = thick / 2 so it straddles y = 0.
local q = { math.cos(math.pi / 4), math.sin(math.pi / 4), 0, 0 }   -- {w, x, y, z}
-- Grip point: over the centre of mass in x (a triangle's centroid: 80 / 3 mm from the right
-- angle) and at its height (60 / 3 mm above the base).
local cx, cz = 0.08 / 3, 0.06 / 3 - sink

local function path(side)   -- side -1: thumb at -y, +1: index at +y
  local function at(t, r, z, yaw)
    -- the finger's point, turned by yaw about the vertical through the grip centre
    local x, y = 0, side * r
    return { t = t, p = { cx + x * math.cos(yaw) - y * math.sin(yaw), x * math.sin(yaw) + y * math.cos(yaw), z } }
  end
  local out, inn = 0.08, thick / 2 - squeeze
  return {
    at(0.0, out, cz, 0), at(1.0, inn, cz, 0), at(1.5, inn, cz, 0),
    at(2.5, inn, cz + lift, 0),          -- lift
    at(3.5, inn, cz + lift, turn),       -- turn about the vertical
  }
end

local function wedge(sim) return sim.objects.wedge end

return {
  name = "mesh_grasp",
  description = "Two fingers pinch a wedge read from an STL file, lift it and turn it 30 degrees.",
  duration = 4.5,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  grasp = locked == 1 and { torsion = "gravity_drop", critical_area = 1e-4 } or nil,
  floor = { height = 0, material = { mu = mu, stiffness = floor_k, damping = floor_c } },
  objects = {
    { name = "wedge", shape = "convex", file = "meshes/wedge_mm.stl", scale = scale, density = density,
      position = { 0, thick / 2, -sink }, orientation = q, material = { mu = mu } },
  },
  fingers = {
    { name = "thumb", stiffness = 400, damping = 3, max_force = 10, trajectory = path(-1) },
    { name = "index", stiffness = 400, damping = 3, max_force = 10, trajectory = path(1) },
  },
  expect = {
    { what = "both fingers grip the wedge before the lift", at = 1.5,
      check = function(sim)
        local t, i = sim.fingers.thumb.touching, sim.fingers.index.touching
        return t == "wedge" and i == "wedge", string.format("thumb on '%s', index on '%s'", t, i)
      end },
    { what = "the wedge is lifted at least 4 cm",
      check = function(sim)
        local rise = wedge(sim).position[3] - wedge(sim.initial).position[3]
        return rise >= 0.04, string.format("rose %.1f mm", rise * 1000)
      end },
    { what = "the wedge turned 30 degrees about the vertical (within 1 degree)",
      check = function(sim)
        -- yaw of the body's x axis (first column of R) relative to the start
        local r, r0 = wedge(sim).rotation, wedge(sim.initial).rotation
        local yaw = math.atan(r[2][1], r[1][1]) - math.atan(r0[2][1], r0[1][1])
        return math.abs(math.deg(yaw) - 30) < 1, string.format("%.2f degrees", math.deg(yaw))
      end },
    { what = "the wedge is held still at the end",
      check = function(sim)
        local v = wedge(sim).velocity
        local speed = math.sqrt(v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2)
        return speed < 0.001, string.format("speed %.2g m/s", speed)
      end },
    { what = "neither finger slips more than 2 mm",
      check = function(sim)
        local s = math.max(sim.fingers.thumb.slip, sim.fingers.index.slip)
        return s < 0.002, string.format("%.3f mm", s * 1000)
      end },
  },
}
