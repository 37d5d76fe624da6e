// libFuzzer harness: PLY (ascii, binary little- and big-endian; geometry/ply_io.h), then
// the manifold check ReadMesh applies (geometry/mesh_topology.h) on what was read.
#include "fuzz/fuzz_support.h"
#include "geometry/mesh_topology.h"
#include "geometry/ply_io.h"

SUBFLOW_FUZZ_QUIET_INITIALIZE()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  subflow::fuzz::RunReader([&] {
    subflow::geometry::VertexProperties properties;
    const subflow::geometry::TriangleMesh mesh = subflow::geometry::ParsePly(bytes, "fuzz.ply", &properties);
    subflow::geometry::MeshTopology(mesh.F, mesh.vertex_count(), "fuzz.ply");
  });
  return 0;
}
