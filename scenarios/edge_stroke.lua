-- edge_stroke: polygon boundary traversal (the paper's section 6 names its absence as a
-- limit).
--
-- A finger with a 4 mm spherical pad presses 2 mm into the top face of a ring (the non-convex
-- triangle mesh scenarios/meshes/ring.obj: 12 mm square section round a 16-gon of radius 30 mm,
-- 128 triangles), strokes outwards across the top face's triangles, over the ring's outer edge
-- and down its outer side, 2 mm deep all the way. The god-object walks from triangle to
-- triangle and, at the convex edge, rolls round it on the edge's cylinder (the pad's exact
-- rounded shape) onto the side face: the contact never ends, never jumps through, and the
-- force pushes the finger back out along the face's normal. The ring is made immovable (no
-- gravity, density x 1e7: 2100 t, so 1 N at 3 cm turns it by 1e-4 rad, 5 um at the finger, in 3 s) so that the finger's path
-- alone decides the contact. mu = 0.3: the finger slides. With a point finger
-- (--set fingers.finger.radius=0) the contact ends at the convex edge, as a frictionless
-- god-object's must (the HIP leaves the body): the first check then fails.
local r = 0.004                       -- m: pad radius
local deep = 0.002                    -- m
local phi = math.rad(11.25)           -- the middle of the first outer face of the 16-gon
local ux, uy = math.cos(phi), math.sin(phi)
local apothem = 0.036 * math.cos(phi) -- m: the outer face's distance from the axis
local top = 0.006                     -- m: the top face
local k = 500                         -- N/m

local function at(t, rho, z) return { t = t, p = { rho * ux, rho * uy, z } } end

-- The stroke: down onto the top face at rho = 30 mm, out to past the edge, down the side.
local path = {
  at(0.0, 0.030, top + r + 0.01),
  at(0.5, 0.030, top + r - deep),              -- press 2 mm into the top face
  at(1.5, apothem + r - deep, top + r - deep), -- out along the top, to over the edge
  at(2.5, apothem + r - deep, -0.003),         -- round the edge and down the side
  at(3.0, apothem + r - deep, -0.003),
}

-- Watch the contact at every servo tick through the feedback view: a trajectory function may
-- read the state of the last physics tick (and keep what it sees in upvalues).
local lost, deepest_inside = false, 0
local function follow(t, sim)
  -- piecewise linear along `path`
  local i = 1
  while i < #path and t > path[i + 1].t do i = i + 1 end
  local a, b = path[i], path[math.min(i + 1, #path)]
  local s = (b.t > a.t) and math.max(0, math.min(1, (t - a.t) / (b.t - a.t))) or 0
  if t > 0.6 and t < 2.9 and sim.fingers.finger.phase == "free" then lost = true end
  return a.p[1] + s * (b.p[1] - a.p[1]), a.p[2] + s * (b.p[2] - a.p[2]), a.p[3] + s * (b.p[3] - a.p[3])
end

return {
  name = "edge_stroke",
  description = "A padded finger strokes over a mesh ring's top face, round its outer edge and down its side without losing contact.",
  duration = 3.0,
  seed = 1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  gravity = { 0, 0, 0 },
  objects = {
    { name = "ring", shape = "mesh", file = "meshes/ring.obj", density = 7.8e10,
      position = { 0, 0, 0 }, material = { mu = 0.3 } },
  },
  fingers = {
    { name = "finger", stiffness = k, damping = 1, radius = r, max_force = 10, trajectory = follow },
  },
  expect = {
    { what = "the contact holds from the press to the end of the stroke (checked at every servo tick)",
      check = function(sim) return not lost, lost and "lost on the way" or "held" end },
    -- At the end the pad is 2 mm into the outer side face: the god-object (the pad's centre) is
    -- on the face pushed out by r, at rho = apothem + r along the stroke's direction, and the force is
    -- k x 2 mm = 1 N pointing out along that face's normal.
    { what = "the god-object ends on the outer side face, pushed out by the pad (rho = apothem + r within 0.1 mm)",
      check = function(sim)
        local go = sim.fingers.finger.god_object
        local rho = go[1] * ux + go[2] * uy
        return math.abs(rho - (apothem + r)) < 1e-4 and go[3] < 0,
          string.format("rho = %.2f mm (expected %.2f), z = %.2f mm", rho * 1000, (apothem + r) * 1000, go[3] * 1000)
      end },
    { what = "the force pushes the finger out along the side face's normal: k x 2 mm = 1 N (within 5%)",
      check = function(sim)
        local f = sim.fingers.finger.force
        local fn = f[1] * ux + f[2] * uy
        return math.abs(fn - k * deep) < 0.05 * k * deep, string.format("f_n = %.3f N", fn)
      end },
  },
}
