-- A trajectory function that writes to the view: a run error naming this file and line.
return {
  duration = 0.1,
  objects = { { name = "box", size = { 0.04, 0.04, 0.04 }, mass = 0.1, position = { 0, 0, 1 } } },
  fingers = {
    { name = "probe", trajectory = function(t, sim)
        if t > 0.05 then sim.objects.box.position[3] = 2 end   -- WRITE
        return 1, 0, 0
      end },
  },
  expect = { { what = "never reached", check = function(sim) return true end } },
}
