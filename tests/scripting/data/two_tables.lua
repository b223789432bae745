-- A scenario that returns two tables: the second would be dropped without a word.
local box = { name = "box", size = { 0.1, 0.1, 0.1 }, mass = 1, position = { 0, 0, 0.05 } }
return { duration = 1, objects = { box } }, { duration = 2, objects = { box } }
