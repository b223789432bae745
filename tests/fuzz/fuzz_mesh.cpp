// libFuzzer harness: the mesh readers (scripting/src/mesh_file.cpp), a file in, then what the
// scenario loader does with what they read (scripting/src/schema.cpp): the closed-solid and
// convexity checks, the principal frame, the engine shape and its mass properties. Built twice,
// GRASPSIM_FUZZ_MESH_SUFFIX ".obj" or ".stl", since the reader goes by the file's extension.
// Property: any bytes are read or refused with a ConversionError naming the file and line or
// triangle; a mesh read is built or refused with a MeshError naming its triangle (-1, or one of
// the mesh's). Anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <utility>

#include "graspsim/engine/shape.hpp"
#include "mesh_file.hpp"
#include "messages.hpp"
#include "tests/fuzz/fuzz_file.hpp"

using namespace graspsim;
using scripting::detail::ConversionError;
using scripting::detail::MeshFile;

namespace {

void build(const MeshFile& file, const std::string& path, bool convex) {
  try {
    if (convex) convex_polyhedron(file.mesh);
    PrincipalFrame frame;
    TriangleMesh body_mesh = to_principal_frame(file.mesh, frame);
    const Shape shape = convex ? convex_shape(std::move(body_mesh)) : mesh_shape(std::move(body_mesh));
    (void)mass_properties(shape, 1.0);
  } catch (const MeshError& e) {
    // The loader names the line of the triangle: it must be one of the file's.
    if (e.triangle() < -1 || e.triangle() >= static_cast<int>(file.origin.size())) std::abort();
    (void)scripting::detail::mesh_location(file, path, e.triangle());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = fuzz::write_scratch(data, size, GRASPSIM_FUZZ_MESH_SUFFIX);
  MeshFile file;
  try {
    file = scripting::detail::read_mesh_file(path);
  } catch (const ConversionError&) {
    return 0;   // refused with its file and line
  }
  // One origin per triangle, as mesh_location needs.
  if (file.origin.size() != file.mesh.triangles.size()) std::abort();
  build(file, path, true);
  build(file, path, false);
  return 0;
}
