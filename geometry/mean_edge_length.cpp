#include "geometry/mean_edge_length.h"

#include "core/error.h"

namespace subflow::geometry {

double MeanEdgeLength(const MeshTopology& topology, const Positions& V) {
  SUBFLOW_CHECK(V.rows() == topology.vertex_count(), "positions of another mesh");
  double sum = 0.0;
  for (int e = 0; e < topology.edge_count(); ++e)
    sum += (V.row(topology.EdgeVertex(e, 0)) - V.row(topology.EdgeVertex(e, 1))).norm();
  return topology.edge_count() > 0 ? sum / topology.edge_count() : 0.0;
}

}  // namespace subflow::geometry
