// Connectivity of an oriented triangle 2-manifold (closed or with boundary), built once
// from F and used by every geometric operator: half-edges, undirected edges, and the
// ordered 1-ring of every vertex.
//
// Conventions
//   half-edge h = 3 f + k runs from F(f, k) to F(f, (k + 1) % 3); its face is h / 3.
//   Ring(v) lists the neighbours of v counter-clockwise (seen from outside, i.e. in the
//   order of the faces' orientation). For a boundary vertex the ring runs from the
//   neighbour a whose half-edge v → a lies on the boundary to the neighbour z whose
//   half-edge z → v lies on the boundary: Ring(v).front() and Ring(v).back() are its two
//   boundary neighbours. RingFaces(v)[k] is the face between Ring(v)[k] and
//   Ring(v)[(k + 1) % valence]; a boundary vertex has valence − 1 ring faces.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// A read-only view of consecutive ints (C++17 has no std::span).
class IndexRange {
 public:
  IndexRange(const int* begin, const int* end) : begin_(begin), end_(end) {}
  const int* begin() const { return begin_; }
  const int* end() const { return end_; }
  int size() const { return static_cast<int>(end_ - begin_); }
  int operator[](int i) const { return begin_[i]; }
  int front() const { return *begin_; }
  int back() const { return *(end_ - 1); }

 private:
  const int* begin_;
  const int* end_;
};

class MeshTopology {
 public:
  // Builds the connectivity of F over `vertex_count` vertices. Throws subflow::Error naming
  // `source` when F is not an oriented 2-manifold: an index out of range, a degenerate
  // face (repeated vertex), an edge shared by more than two faces, two faces with
  // opposite orientation, or a vertex whose faces form more than one fan.
  // Vertices referenced by no face are allowed (valence 0); see UnreferencedVertexCount().
  MeshTopology(const Faces& F, int vertex_count, const std::string& source = "mesh");

  int vertex_count() const { return vertex_count_; }
  int face_count() const { return face_count_; }
  int edge_count() const { return static_cast<int>(edge_vertices_.size() / 2); }

  // Half-edges.
  int HalfedgeSource(int h) const { return faces_[h]; }
  int HalfedgeTarget(int h) const { return faces_[3 * (h / 3) + (h % 3 + 1) % 3]; }
  // The vertex of h's face opposite to h.
  int HalfedgeOpposite(int h) const { return faces_[3 * (h / 3) + (h % 3 + 2) % 3]; }
  // The half-edge running the other way on the neighbouring face, or −1 on the boundary.
  int HalfedgeTwin(int h) const { return halfedge_twin_[h]; }

  // Undirected edges, numbered in order of first appearance over the half-edges.
  int EdgeVertex(int e, int i) const { return edge_vertices_[2 * e + i]; }
  // A half-edge of edge e (the one from EdgeVertex(e,0) to EdgeVertex(e,1)).
  int EdgeHalfedge(int e) const { return edge_halfedge_[e]; }
  bool IsBoundaryEdge(int e) const { return halfedge_twin_[edge_halfedge_[e]] < 0; }
  int FaceEdge(int f, int k) const { return halfedge_edge_[3 * f + k]; }

  // Vertices.
  IndexRange Ring(int v) const {
    return {ring_.data() + ring_offset_[v], ring_.data() + ring_offset_[v + 1]};
  }
  IndexRange RingFaces(int v) const {
    return {ring_faces_.data() + ring_face_offset_[v],
            ring_faces_.data() + ring_face_offset_[v + 1]};
  }
  int Valence(int v) const { return ring_offset_[v + 1] - ring_offset_[v]; }
  bool IsBoundaryVertex(int v) const { return is_boundary_vertex_[v] != 0; }

  bool IsClosed() const { return boundary_edge_count_ == 0; }
  int BoundaryEdgeCount() const { return boundary_edge_count_; }
  int UnreferencedVertexCount() const { return unreferenced_vertex_count_; }
  // Number of connected components of the face graph.
  int ComponentCount() const;

 private:
  int vertex_count_ = 0;
  int face_count_ = 0;
  std::vector<int> faces_;  // 3 per face, copied from F
  std::vector<int> halfedge_twin_;
  std::vector<int> halfedge_edge_;
  std::vector<int> edge_vertices_;  // 2 per edge
  std::vector<int> edge_halfedge_;
  std::vector<int> ring_offset_, ring_;
  std::vector<int> ring_face_offset_, ring_faces_;
  std::vector<char> is_boundary_vertex_;
  int boundary_edge_count_ = 0;
  int unreferenced_vertex_count_ = 0;
};

}  // namespace subflow::geometry
