// Mesh files (OBJ, STL) for convex and mesh objects: the loader reads them, never the engine
// and never Lua. Plain C++; errors are ConversionErrors naming the file and line (OBJ, ASCII
// STL) or triangle (binary STL).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "graspsim/engine/shape.hpp"

namespace graspsim::scripting::detail {

// The largest mesh file read, in bytes (64 MiB: a binary STL of 1.3 million triangles, an ASCII
// one of about 270,000; the library's meshes are under 6 kB). Bounds the memory and time a
// scenario's mesh can take before its triangles are checked.
inline constexpr std::uint64_t kMaxMeshFileBytes = 64ull << 20;

struct MeshFile {
  TriangleMesh mesh;                  // file units; vertices at exactly the same position merged
  std::vector<std::string> origin;    // per triangle: "path:line" or "path: triangle n" (1-based)
};

// Reads an OBJ (.obj) or STL (.stl, ASCII or binary) file, by its extension (case-insensitive).
// Only a regular file of at most kMaxMeshFileBytes: a directory, a FIFO, a device (a link to
// /dev/zero), a socket or a larger file is refused at once, naming the reason.
// OBJ: v and f lines (polygons fan-triangulated, negative indices, v/vt/vn forms), comments;
// vt, vn, vp, o, g, s, usemtl, mtllib ignored, any other statement refused. STL: binary when the
// size is exactly 84 + 50 n for the n in its header (even if it starts with "solid"), else ASCII.
// Triangles whose corners coincide after merging are dropped (they enclose nothing).
MeshFile read_mesh_file(const std::string& path);

// "path:line: " (or "path: triangle n: ") for triangle t of the file, "path: " for t < 0.
std::string mesh_location(const MeshFile& file, const std::string& path, int triangle);

}  // namespace graspsim::scripting::detail
