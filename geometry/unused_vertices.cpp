#include "geometry/unused_vertices.h"

namespace subflow::geometry {

int RemoveUnusedVertices(TriangleMesh* mesh, std::vector<int>* old_to_new) {
  const int n = mesh->vertex_count();
  std::vector<int> index(n, -1);
  for (int f = 0; f < mesh->face_count(); ++f)
    for (int k = 0; k < 3; ++k) index[mesh->F(f, k)] = 0;
  int kept = 0;
  for (int v = 0; v < n; ++v)
    if (index[v] == 0) index[v] = kept++;
  if (kept < n) {
    Positions V(kept, 3);
    for (int v = 0; v < n; ++v)
      if (index[v] >= 0) V.row(index[v]) = mesh->V.row(v);
    mesh->V = std::move(V);
    for (int f = 0; f < mesh->face_count(); ++f)
      for (int k = 0; k < 3; ++k) mesh->F(f, k) = index[mesh->F(f, k)];
  }
  if (old_to_new) *old_to_new = std::move(index);
  return n - kept;
}

}  // namespace subflow::geometry
