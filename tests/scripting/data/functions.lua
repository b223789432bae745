-- Lua-function trajectories and expectations, for the run-time tests.
local function circle(t)
  return 0.1 * math.cos(t), 0.1 * math.sin(t), 0.04
end
return {
  duration = 3,
  seed = 11,
  objects = { { name = "box", size = {0.08, 0.08, 0.08}, mass = 0.4, position = {0, 0, 0.04} } },
  fingers = {
    { name = "thumb", trajectory = circle },
    { name = "index", trajectory = function(t) return {t, 2 * t, 0.5} end },
    { name = "ring", trajectory = function(t)
        if t > 1 then error("the ring finger only moves for 1 s") end  -- TRAJECTORY ERROR
        return 0, 0, t
      end },
    { name = "pinky", trajectory = function(t)
        if t < 1 then return "left", 0, 0 end
        if t < 2 then return 0 / 0, 0, 0 end
        return {1, 2}
      end },
    { name = "random", trajectory = function(t) return math.random(), 0, 0 end },
    { name = "stuck", trajectory = function(t) while true do end end },
  },
  expect = {
    { what = "box lifted at least 5 cm", at = 2.5,
      check = function(sim)
        local z = sim.objects.box.position[3]
        return z - sim.initial.objects.box.position[3] >= 0.05, string.format("z = %.3f m", z)
      end },
    { what = "forgets to return", check = function(sim) local unused = sim.time end },
    { what = "thumb touches the box",
      check = function(sim)
        local f = sim.fingers.thumb
        return f.touching == "box" and f.force[1] > 0 and f.slip < 0.01, f.touching
      end },
    { what = "reads a missing object",
      check = function(sim) return sim.objects.lid.position[3] > 0 end },  -- CHECK ERROR
  },
}
