// Mesh files (OBJ, STL) for convex and mesh objects: the loader reads them, never the engine
// and never Lua. Plain C++; errors are ConversionErrors naming the file and line (OBJ, ASCII
// STL) or triangle (binary STL).
#pragma once

#include <string>
#include <vector>

#include "graspsim/engine/shape.hpp"

namespace graspsim::scripting::detail {

struct MeshFile {
  TriangleMesh mesh;                  // file units; vertices at exactly the same position merged
  std::vector<std::string> origin;    // per triangle: "path:line" or "path: triangle n" (1-based)
};

// Reads an OBJ (.obj) or STL (.stl, ASCII or binary) file, by its extension (case-insensitive).
// OBJ: v and f lines (polygons fan-triangulated, negative indices, v/vt/vn forms), comments;
// vt, vn, vp, o, g, s, usemtl, mtllib ignored, any other statement refused. STL: binary when the
// size is exactly 84 + 50 n for the n in its header (even if it starts with "solid"), else ASCII.
// Triangles whose corners coincide after merging are dropped (they enclose nothing).
MeshFile read_mesh_file(const std::string& path);

// "path:line: " (or "path: triangle n: ") for triangle t of the file, "path: " for t < 0.
std::string mesh_location(const MeshFile& file, const std::string& path, int triangle);

}  // namespace graspsim::scripting::detail
