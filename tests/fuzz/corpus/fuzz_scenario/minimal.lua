-- The smallest useful scenario: everything not given takes the documented default.
return {
  duration = 1,
  objects = { { name = "box", size = {0.1, 0.1, 0.1}, mass = 1 } },
  fingers = { { name = "thumb", trajectory = { {t = 0, p = {0, 0, 0.2}} } } },
}
