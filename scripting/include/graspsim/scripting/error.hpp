// The one exception scripting/ throws: bad scenario input, with a message written for the user.
#pragma once

#include <stdexcept>

namespace graspsim::scripting {

// Bad scenario input (file, syntax, runtime error, unknown field, bad value). what() is the
// whole message for the user: "path:line: ..." or "path: objects[1] 'box': mass: must be > 0".
class ScenarioError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace graspsim::scripting
