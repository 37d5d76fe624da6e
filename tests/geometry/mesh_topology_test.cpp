#include "geometry/mesh_topology.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace subflow::geometry {
namespace {

Faces Tetrahedron() {
  Faces F(4, 3);
  F << 0, 2, 1,  //
      0, 1, 3,   //
      1, 2, 3,   //
      2, 0, 3;
  return F;
}

TEST(MeshTopology, ClosedTetrahedronHasValenceThreeRingsInFaceOrder) {
  const MeshTopology topology(Tetrahedron(), 4);
  EXPECT_TRUE(topology.IsClosed());
  EXPECT_EQ(topology.edge_count(), 6);
  EXPECT_EQ(topology.ComponentCount(), 1);
  for (int v = 0; v < 4; ++v) {
    ASSERT_EQ(topology.Valence(v), 3);
    EXPECT_EQ(topology.RingFaces(v).size(), 3);
    // Consecutive ring neighbours (v, a, b) must form a face with the mesh's orientation.
    for (int k = 0; k < 3; ++k) {
      const int f = topology.RingFaces(v)[k];
      const int a = topology.Ring(v)[k], b = topology.Ring(v)[(k + 1) % 3];
      const Faces F = Tetrahedron();
      bool found = false;
      for (int r = 0; r < 3; ++r)
        found |= F(f, r) == v && F(f, (r + 1) % 3) == a && F(f, (r + 2) % 3) == b;
      EXPECT_TRUE(found) << "vertex " << v << " ring position " << k;
    }
  }
}

TEST(MeshTopology, OpenFanHasBoundaryNeighboursAtRingEnds) {
  // Vertex 0 at the centre of three triangles forming a half-disk: 1, 2, 3, 4 around it.
  Faces F(3, 3);
  F << 0, 1, 2,  //
      0, 2, 3,   //
      0, 3, 4;
  const MeshTopology topology(F, 5);
  EXPECT_FALSE(topology.IsClosed());
  EXPECT_EQ(topology.BoundaryEdgeCount(), 5);
  ASSERT_EQ(topology.Valence(0), 4);
  EXPECT_TRUE(topology.IsBoundaryVertex(0));
  EXPECT_EQ(topology.Ring(0).front(), 1);
  EXPECT_EQ(topology.Ring(0).back(), 4);
  EXPECT_EQ(topology.RingFaces(0).size(), 3);
}

TEST(MeshTopology, RejectsEdgeSharedByThreeFaces) {
  Faces F(3, 3);
  F << 0, 1, 2,  //
      1, 0, 3,   //
      1, 0, 4;
  EXPECT_THROW(MeshTopology(F, 5, "fin.ply"), Error);
  try {
    MeshTopology(F, 5, "fin.ply");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fin.ply"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("non-manifold"), std::string::npos);
  }
}

TEST(MeshTopology, RejectsInconsistentOrientation) {
  Faces F(2, 3);
  F << 0, 1, 2,  //
      0, 1, 3;
  EXPECT_THROW(MeshTopology(F, 4), Error);
}

TEST(MeshTopology, RejectsBowtieVertex) {
  // Two triangles touching only at vertex 0.
  Faces F(2, 3);
  F << 0, 1, 2,  //
      0, 3, 4;
  EXPECT_THROW(MeshTopology(F, 5), Error);
}

TEST(MeshTopology, RejectsOutOfRangeAndDegenerateFaces) {
  Faces F(1, 3);
  F << 0, 1, 7;
  EXPECT_THROW(MeshTopology(F, 3), Error);
  F << 0, 1, 1;
  EXPECT_THROW(MeshTopology(F, 3), Error);
}

}  // namespace
}  // namespace subflow::geometry
