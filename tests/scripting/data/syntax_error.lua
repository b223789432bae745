-- A scenario with a syntax error: a missing comma.
return {
  duration = 1
  seed = 2,  -- SYNTAX ERROR HERE
}
