-- One finger on a floor with friction, for python/tests/test_drive.py: the test moves the
-- finger's HIP itself (drive = {"finger"}); the trajectory only holds it 1 cm above the floor.
-- No gravity, and the one box (a scenario needs a body) 1 m away, so nothing moves but the finger.
return {
  name = "finger_on_floor",
  duration = 0.1,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  gravity = { 0, 0, 0 },
  floor = { height = 0, material = { mu = 0.5 } },   -- surface stiffness unset: rigid
  objects = {
    { name = "box", shape = "box", size = { 0.1, 0.1, 0.1 }, mass = 1, position = { 1, 0, 0.05 } },
  },
  fingers = {
    { name = "finger", stiffness = 400, damping = 0, max_force = 10,
      trajectory = { { t = 0, p = { 0, 0, 0.01 } } } },
  },
}
