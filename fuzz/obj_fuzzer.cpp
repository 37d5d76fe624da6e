// libFuzzer harness: Wavefront OBJ (geometry/obj_io.h), then the manifold check ReadMesh
// applies (geometry/mesh_topology.h) on what was read.
#include "fuzz/fuzz_support.h"
#include "geometry/mesh_topology.h"
#include "geometry/obj_io.h"

SUBFLOW_FUZZ_QUIET_INITIALIZE()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  subflow::fuzz::RunReader([&] {
    const subflow::geometry::TriangleMesh mesh = subflow::geometry::ParseObj(text, "fuzz.obj");
    subflow::geometry::MeshTopology(mesh.F, mesh.vertex_count(), "fuzz.obj");
  });
  return 0;
}
