local sizes = nil
return {
  duration = 1.0,
  objects = { { name = "box", size = sizes[1], mass = 1 } },
}
