// The mean length of a mesh's undirected edges, Σ_e |V(a_e) − V(b_e)| / #E over the edges
// of `topology` (each edge once, boundary or not), in the units of V. The length scale of
// a level of the hierarchy: the automatic visibility tolerance, the largest normal
// correction of motion initialization, the unit of the refinement's steps and weights.
#pragma once

#include "geometry/mesh_topology.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// V: #V×3 positions of the topology's vertices. 0 for a mesh without edges.
double MeanEdgeLength(const MeshTopology& topology, const Positions& V);

}  // namespace subflow::geometry
