-- A floor far too stiff for 50 Hz physics: 12 k / m h^2 = 12 x 1e6 / 0.1 x 4e-4 = 48000, far
-- past the explicit bound of 4. The run must warn, then stop when the box's state stops being
-- finite, instead of finishing and "passing".
return {
  integrator = "paper",   -- the explicit step, which the stiffness breaks
  duration = 10,
  floor = { material = { stiffness = 1e6, damping = 0 } },
  objects = { { name = "box", size = { 0.1, 0.1, 0.1 }, mass = 0.1, position = { 0, 0, 0.051 } } },
  expect = { { what = "the box stays near the floor", check = function(sim) return sim.objects.box.position[3] < 1 end } },
}
