-- A valid scenario that uses every field of the format; the loader test checks each value.
return {
  name = "two_box_grasp",
  description = "two fingers squeeze a box off the floor",
  duration = 2.5,
  seed = 7,
  rates = { servo = 3000, haptic = 1000, physics = 100 },
  gravity = {0, 0, -9.81},
  floor = { height = -0.01, material = { mu = 0.9, stiffness = 2000, damping = 12 } },
  objects = {
    { name = "box", shape = "box", size = {0.08, 0.06, 0.04}, mass = 0.4,
      position = {0, 0, 0.02},
      material = { mu = 0.8, stiffness = 250, damping = 5 } },
    { name = "lid", size = {0.1, 0.1, 0.01}, density = 780, inertia = {1e-4, 2e-4, 2.5e-4},
      position = {0, 0, 0.1}, orientation = {2^-0.5, 0, 0, 2^-0.5},
      velocity = {0.1, 0, 0}, angular_velocity = {0, 0, 1} },
  },
  fingers = {
    { name = "thumb", stiffness = 400, damping = 3.5, max_force = 8,
      trajectory = { {t = 0, p = {-0.1, 0, 0.02}}, {t = 1, p = {-0.03, 0, 0.02}} } },
    { name = "index", interpolation = "linear",
      trajectory = { {t = 0, p = {0.1, 0, 0.02}}, {t = 1, p = {0.03, 0, 0.02}},
                     {t = 2, p = {0.03, 0, 0.1}} } },
  },
  expect = {
    { what = "box lifted", at = 2,
      check = function(sim) return sim.objects.box.position[3] > 0.05 end },
  },
}
