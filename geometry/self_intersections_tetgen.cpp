#include <algorithm>
#include <array>
#include <chrono>
#include <map>

#include <tetgen.h>

#include "geometry/self_intersections.h"

namespace subflow::geometry {
namespace {

using Triple = std::array<int, 3>;

Triple Sorted(int a, int b, int c) {
  Triple t{a, b, c};
  std::sort(t.begin(), t.end());
  return t;
}

}  // namespace

SelfIntersectionResult FindSelfIntersectionsTetgen(const TriangleMesh& mesh) {
  const auto start = std::chrono::steady_clock::now();
  SelfIntersectionResult result;
  result.method = "TetGen";
  const int n = mesh.vertex_count();
  if (!mesh.V.allFinite()) {
    result.note = "not run: the mesh has non-finite coordinates";
    return result;
  }
  std::vector<int> input_faces;  // the faces handed to TetGen
  for (int f = 0; f < mesh.face_count(); ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    if (std::min({a, b, c}) < 0 || std::max({a, b, c}) >= n) {
      result.note = "not run: face " + std::to_string(f) + " has a vertex index out of range";
      return result;
    }
    if (a != b && b != c && a != c) input_faces.push_back(f);
  }

  // tetgenio owns and frees these arrays (delete[]), so they are allocated with new[].
  // TetGen's predicates assert (abort) when the bounding box is flat along an axis, as
  // it is for a planar patch; then one extra point, on no face, lifts the box off that
  // plane (a point on no face cannot change which faces intersect). Only then: a bigger
  // box makes TetGen's bisection of the faces much less effective.
  Eigen::RowVector3d low = Eigen::RowVector3d::Zero(), high = Eigen::RowVector3d::Zero();
  if (n > 0) {
    low = mesh.V.colwise().minCoeff();
    high = mesh.V.colwise().maxCoeff();
  }
  const Eigen::RowVector3d extent = high - low;
  const bool flat = !(extent.minCoeff() > 0.0);
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = n + (flat ? 1 : 0);
  in.pointlist = new REAL[3 * static_cast<size_t>(in.numberofpoints)];
  for (int v = 0; v < n; ++v)
    for (int axis = 0; axis < 3; ++axis) in.pointlist[3 * v + axis] = mesh.V(v, axis);
  if (flat) {
    const double lift = extent.maxCoeff() > 0.0 ? extent.maxCoeff() : 1.0;
    for (int axis = 0; axis < 3; ++axis)
      in.pointlist[3 * n + axis] =
          extent(axis) > 0.0 ? 0.5 * (low(axis) + high(axis)) : low(axis) + lift;
  }
  in.numberoffacets = static_cast<int>(input_faces.size());
  in.facetlist = new tetgenio::facet[input_faces.size()];
  for (size_t i = 0; i < input_faces.size(); ++i) {
    tetgenio::facet& facet = in.facetlist[i];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = mesh.F(input_faces[i], k);
  }

  char switches[] = "pdQ";
  try {
    tetrahedralize(switches, &in, &out);
  } catch (int code) {
    // TetGen's terminatetetgen codes: 1 out of memory, 2 internal error, 3 self-
    // intersection it could not resolve, 4 very small input feature, 10 bad input.
    result.note = "TetGen stopped with error code " + std::to_string(code);
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  }

  // With -d TetGen outputs its nodes and the intersecting faces only; map them back to
  // our faces through the (sorted) vertex triple.
  std::vector<int> to_input_vertex(out.numberofpoints, -1);
  if (out.numberofpoints == in.numberofpoints) {
    for (int v = 0; v < n; ++v) to_input_vertex[v] = v;
  } else if (out.numberofpoints > 0) {  // TetGen renumbered: match coordinates exactly
    std::map<std::array<double, 3>, int> by_position;
    for (int v = n - 1; v >= 0; --v) by_position[{mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)}] = v;
    for (int v = 0; v < out.numberofpoints; ++v) {
      const auto it = by_position.find(
          {out.pointlist[3 * v], out.pointlist[3 * v + 1], out.pointlist[3 * v + 2]});
      if (it != by_position.end()) to_input_vertex[v] = it->second;
    }
  }
  std::map<Triple, std::vector<int>> faces_by_triple;
  for (int f : input_faces)
    faces_by_triple[Sorted(mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2))].push_back(f);
  int unmatched = 0;
  for (int t = 0; t < out.numberoftrifaces; ++t) {
    int corner[3];
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      const int v = out.trifacelist[3 * t + k] - out.firstnumber;
      corner[k] = (v >= 0 && v < out.numberofpoints) ? to_input_vertex[v] : -1;
      ok &= corner[k] >= 0;
    }
    const auto it =
        ok ? faces_by_triple.find(Sorted(corner[0], corner[1], corner[2])) : faces_by_triple.end();
    if (it == faces_by_triple.end()) {
      ++unmatched;
      continue;
    }
    result.intersecting_faces.insert(result.intersecting_faces.end(), it->second.begin(),
                                     it->second.end());
  }
  std::sort(result.intersecting_faces.begin(), result.intersecting_faces.end());
  result.intersecting_faces.erase(
      std::unique(result.intersecting_faces.begin(), result.intersecting_faces.end()),
      result.intersecting_faces.end());
  result.ran = true;
  result.reported_face_count = static_cast<int>(result.intersecting_faces.size()) + unmatched;
  if (unmatched > 0)
    result.note =
        std::to_string(unmatched) + " intersecting faces reported by TetGen match no input face";
  if (input_faces.size() != static_cast<size_t>(mesh.face_count()))
    result.note += std::string(result.note.empty() ? "" : "; ") +
                   std::to_string(mesh.face_count() - static_cast<int>(input_faces.size())) +
                   " faces repeating a vertex were left out";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace subflow::geometry
