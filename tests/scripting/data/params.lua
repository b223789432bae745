-- A scenario with parameters: each param(name, default) can be changed with --set name=value.
local lift = param("lift", 0.05)           -- m: how high the fingers raise the box
local label = param("label", "plain")
local use_floor = param("use_floor", true)
local start = param("start", {-0.1, 0, 0.04})
return {
  description = label,
  duration = 2,
  floor = use_floor and { material = { stiffness = 1000, damping = 10 } } or false,
  objects = { { name = "box", size = {0.08, 0.08, 0.08}, mass = 0.4, position = {0, 0, 0.04},
                material = { stiffness = 500 } } },
  fingers = { { name = "thumb",
                trajectory = { {t = 0, p = start}, {t = 1, p = {start[1], start[2], start[3] + lift}} } } },
}
