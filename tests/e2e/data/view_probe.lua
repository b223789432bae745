-- The view a trajectory function gets as its second argument is the state the last physics tick
-- left: a falling box (no floor) watched by a free finger far away, which remembers what it saw.
-- The checks compare that with what a check sees at the same tick (the same state, read the
-- same way), and count how often the view changed.
local seen = { time = -1, z = 0, changes = 0, pitch = 0 }
return {
  duration = 0.2,
  rates = { servo = 3000, haptic = 500, physics = 50 },
  objects = { { name = "box", size = { 0.04, 0.04, 0.04 }, mass = 0.1, position = { 0, 0, 1 } } },
  fingers = {
    { name = "probe", trajectory = function(t, sim)
        if sim.time ~= seen.time then seen.changes = seen.changes + 1 end
        seen.time, seen.z = sim.time, sim.objects.box.position[3]
        seen.rows = #sim.objects.box.rotation
        seen.phase = sim.fingers.probe.phase
        return 1, 0, 0, 0.25 * t   -- x, y, z (m), pitch (rad)
      end },
  },
  expect = {
    { what = "the view is the state a check sees", at = 0.105,
      check = function(sim)
        return seen.z == sim.objects.box.position[3] and seen.z < 1,
               string.format("view z %.17g, check z %.17g", seen.z, sim.objects.box.position[3])
      end },
    -- At tick 315 the last physics tick was tick 300, after which the clock read 301 / 3000 s.
    { what = "the view is as of the last physics tick", at = 0.105,
      check = function(sim)
        return seen.time == 301 / 3000, string.format("view time %.17g", seen.time)
      end },
    -- The initial view, then one per physics tick before 315 (ticks 0, 60, ..., 300): 7.
    { what = "the view changed once per physics tick", at = 0.105,
      check = function(sim) return seen.changes == 7, tostring(seen.changes) end },
    { what = "the view has a rotation matrix and a phase", at = 0.105,
      check = function(sim) return seen.rows == 3 and seen.phase == "free", tostring(seen.phase) end },
  },
}
