// Normals of a triangle mesh (faces counter-clockwise seen from outside):
//   face normal      n_f = (v1 − v0) × (v2 − v0) / |…|  (outward for a closed surface)
//   vertex normal    n_v = Σ_{f ∋ v} (v1 − v0) × (v2 − v0) / |…|, i.e. the face normals
//                    weighted by twice the face areas, normalized.
// Degenerate faces contribute nothing; a vertex with no non-degenerate face gets (0,0,0).
#pragma once

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

Positions FaceNormals(const Positions& V, const Faces& F);    // #F×3, unit rows
Positions VertexNormals(const Positions& V, const Faces& F);  // #V×3, unit rows
Eigen::VectorXd FaceAreas(const Positions& V, const Faces& F);  // #F

}  // namespace subflow::geometry
