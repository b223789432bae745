-- A finger on a Lua function that reads the view, a param and an expectation.
local depth = param("depth", 0.01)   -- m: how far the finger presses
return {
  duration = 0.5,
  rates = { servo = 1000, haptic = 500, physics = 100 },
  floor = { material = { mu = 0.5 } },
  objects = { { name = "box", size = {0.1, 0.1, 0.1}, mass = 1, position = {0, 0, 0.05} } },
  fingers = { { name = "index", trajectory = function(t, sim)
    if sim == nil then return 0, 0, 0.12 end
    return 0, 0, 0.12 - depth * math.min(t * 4, 1) + 0 * sim.objects.box.position[3]
  end } },
  expect = { { what = "box stays", at = 0.4,
               check = function(sim) return sim.objects.box.position[3] < 0.2 end } },
}
