#include "geometry/mesh_topology.h"

#include <algorithm>
#include <numeric>

#include "core/error.h"

namespace subflow::geometry {
namespace {

std::string VertexField(int v) { return "vertex " + std::to_string(v); }
std::string FaceField(int f) { return "face " + std::to_string(f); }

}  // namespace

MeshTopology::MeshTopology(const Faces& F, int vertex_count, const std::string& source)
    : vertex_count_(vertex_count), face_count_(static_cast<int>(F.rows())) {
  const int n = vertex_count_;
  const int m = face_count_;
  faces_.resize(3 * static_cast<size_t>(m));
  for (int f = 0; f < m; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int v = F(f, k);
      if (v < 0 || v >= n)
        ThrowError(source, FaceField(f),
                   "vertex index " + std::to_string(v) + " out of range [0, " +
                       std::to_string(n) + ")");
      faces_[3 * f + k] = v;
    }
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2))
      ThrowError(source, FaceField(f), "degenerate triangle (a vertex is repeated)");
  }

  // Outgoing half-edges per vertex in CSR layout; valences are small, so a linear scan of
  // a vertex's outgoing list finds a half-edge faster than any hash map.
  const int halfedge_count = 3 * m;
  std::vector<int> out_offset(n + 1, 0);
  for (int h = 0; h < halfedge_count; ++h) ++out_offset[faces_[h] + 1];
  std::partial_sum(out_offset.begin(), out_offset.end(), out_offset.begin());
  std::vector<int> out_halfedges(halfedge_count);
  {
    std::vector<int> fill(out_offset.begin(), out_offset.end() - 1);
    for (int h = 0; h < halfedge_count; ++h) out_halfedges[fill[faces_[h]]++] = h;
  }
  auto find_halfedge = [&](int from, int to) {
    for (int i = out_offset[from]; i < out_offset[from + 1]; ++i)
      if (HalfedgeTarget(out_halfedges[i]) == to) return out_halfedges[i];
    return -1;
  };

  // Twins, and the two ways a surface fails to be an oriented manifold along an edge.
  halfedge_twin_.assign(halfedge_count, -1);
  for (int v = 0; v < n; ++v) {
    for (int i = out_offset[v]; i < out_offset[v + 1]; ++i) {
      const int h = out_halfedges[i];
      const int w = HalfedgeTarget(h);
      for (int j = i + 1; j < out_offset[v + 1]; ++j)
        if (HalfedgeTarget(out_halfedges[j]) == w)
          ThrowError(source, "edge (" + std::to_string(v) + ", " + std::to_string(w) + ")",
                     "non-manifold or inconsistently oriented: faces " +
                         std::to_string(h / 3) + " and " +
                         std::to_string(out_halfedges[j] / 3) +
                         " both traverse it in the same direction (an edge may border at "
                         "most two faces, with opposite orientations)");
      halfedge_twin_[h] = find_halfedge(w, v);
    }
  }

  // Undirected edges.
  halfedge_edge_.assign(halfedge_count, -1);
  for (int h = 0; h < halfedge_count; ++h) {
    if (halfedge_edge_[h] >= 0) continue;
    const int e = static_cast<int>(edge_halfedge_.size());
    edge_halfedge_.push_back(h);
    edge_vertices_.push_back(HalfedgeSource(h));
    edge_vertices_.push_back(HalfedgeTarget(h));
    halfedge_edge_[h] = e;
    if (halfedge_twin_[h] >= 0) halfedge_edge_[halfedge_twin_[h]] = e;
    else ++boundary_edge_count_;
  }

  // Ordered 1-rings. The face (v, a, b) continues counter-clockwise into the face holding
  // the half-edge v → b; a fan starts where the half-edge into v has no twin.
  ring_offset_.assign(n + 1, 0);
  ring_face_offset_.assign(n + 1, 0);
  is_boundary_vertex_.assign(n, 0);
  ring_.reserve(halfedge_count + boundary_edge_count_);
  ring_faces_.reserve(halfedge_count);
  for (int v = 0; v < n; ++v) {
    const int fan_faces = out_offset[v + 1] - out_offset[v];
    if (fan_faces == 0) {
      ++unreferenced_vertex_count_;
    } else {
      // Start at an outgoing half-edge whose face has no predecessor (boundary), if any.
      int start = out_halfedges[out_offset[v]];
      for (int i = out_offset[v]; i < out_offset[v + 1]; ++i) {
        const int h = out_halfedges[i];  // v → a; the face's predecessor would hold a → v
        if (halfedge_twin_[h] < 0) {
          start = h;
          is_boundary_vertex_[v] = 1;
          break;
        }
      }
      int h = start;
      int walked = 0;
      while (true) {
        ring_.push_back(HalfedgeTarget(h));
        ring_faces_.push_back(h / 3);
        ++walked;
        const int into_v = 3 * (h / 3) + (h % 3 + 2) % 3;  // b → v
        const int next = halfedge_twin_[into_v];          // v → b on the next face
        if (next < 0) {                                    // reached the other boundary
          ring_.push_back(HalfedgeSource(into_v));
          break;
        }
        if (next == start) break;
        if (walked > fan_faces) break;  // cannot happen on valid input; guards the loop
        h = next;
      }
      if (walked != fan_faces)
        ThrowError(source, VertexField(v),
                   "non-manifold vertex: its " + std::to_string(fan_faces) +
                       " faces form more than one fan (expected a single disk or half-disk)");
    }
    ring_offset_[v + 1] = static_cast<int>(ring_.size());
    ring_face_offset_[v + 1] = static_cast<int>(ring_faces_.size());
  }
}

int MeshTopology::ComponentCount() const {
  std::vector<int> parent(face_count_);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (int h = 0; h < 3 * face_count_; ++h) {
    const int t = halfedge_twin_[h];
    if (t >= 0) parent[find(h / 3)] = find(t / 3);
  }
  int count = 0;
  for (int f = 0; f < face_count_; ++f) count += find(f) == f;
  return count;
}

}  // namespace subflow::geometry
