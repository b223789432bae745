-- Neither the floor nor the box says how the contact is damped (both unset, i.e. infinite):
-- inf x 0 would be NaN at the first contact, so the scenario must be refused.
return {
  integrator = "paper",   -- the paper's step refuses it; the implicit one chooses a damping
  duration = 1,
  floor = { material = { stiffness = 100 } },
  objects = { { name = "box", size = { 0.1, 0.1, 0.1 }, mass = 0.1, position = { 0, 0, 0.05 } } },
}
