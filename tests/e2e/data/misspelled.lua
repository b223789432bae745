return { duration = 1.0, objects = { { name = "box", size = { 1, 1, 1 }, mas = 1 } } }
