// JSON text for what graspsim writes as JSON (`graspsim compare --json`, the view's scene and
// events): one string escaper for all of them.
#pragma once

#include <string>

namespace graspsim::app {

// `text` as a JSON string literal, quotes included: '"' and '\' escaped, line feed, carriage
// return and tab as \n \r \t, every other byte below 0x20 as \u00XX (RFC 8259 section 7); all
// other bytes as they are.
std::string json_string(const std::string& text);

}  // namespace graspsim::app
