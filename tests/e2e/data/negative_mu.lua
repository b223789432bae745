return { duration = 1.0, objects = { { name = "box", size = { 1, 1, 1 }, mass = 1, material = { mu = -0.5 } } } }
