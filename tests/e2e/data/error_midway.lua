-- The finger's script fails at t = 0.5 s: the run must stop, keep its trace, and say why.
return {
  duration = 1.0,
  objects = { { name = "box", size = { 0.1, 0.1, 0.1 }, mass = 1, position = { 0, 0, 1 } } },
  fingers = {
    { name = "finger", stiffness = 100,
      trajectory = function(t)
        if t >= 0.5 then error("the hand slipped off the script") end
        return 1, 0, 0
      end },
  },
}
