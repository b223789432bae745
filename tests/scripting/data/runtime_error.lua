-- A scenario that fails while it runs: indexing a nil value.
local sizes = {}
local function edge(name)
  return sizes[name].x  -- RUNTIME ERROR HERE
end
return { duration = edge("box") }
