-- A scenario that forgets to return its table.
local scenario = { duration = 1 }
