-- A box falls freely for 0.2 s; the expectation that it stays up must fail (exit status 1).
return {
  duration = 0.2,
  objects = { { name = "box", size = { 0.1, 0.1, 0.1 }, mass = 1, position = { 0, 0, 1 } } },
  expect = {
    { what = "the box stays up", check = function(sim) return sim.objects.box.position[3] > 0.99 end },
  },
}
