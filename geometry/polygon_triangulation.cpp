#include "geometry/polygon_triangulation.h"

#include <array>
#include <cmath>

#include <Eigen/Geometry>

#include "core/error.h"

namespace subflow::geometry {
namespace {

using Point2 = std::array<double, 2>;

double Cross(const Point2& a, const Point2& b, const Point2& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

// p inside or on triangle abc (counter-clockwise), but not one of its corners.
bool InTriangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
  if (p == a || p == b || p == c) return false;
  return Cross(a, b, p) >= 0 && Cross(b, c, p) >= 0 && Cross(c, a, p) >= 0;
}

// Ear clipping of one polygon (corner indices `corner` into V), appending to `out`.
void ClipEars(const int* corner, int k, const Positions& V, std::vector<std::array<int, 3>>* out) {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (int i = 0; i < k; ++i) {
    const Eigen::Vector3d p = V.row(corner[i]), q = V.row(corner[(i + 1) % k]);
    normal += (p - q).cross(p + q) / 2.0;
  }
  int drop = 0;
  normal.cwiseAbs().maxCoeff(&drop);
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  // Seen along +normal, (u, v) turn counter-clockwise when normal[drop] > 0; flip v
  // otherwise so that the polygon is counter-clockwise in 2D. A zero normal (degenerate
  // polygon) leaves no ear: the most-convex fallback below still triangulates it.
  const double flip = normal[drop] < 0 ? -1.0 : 1.0;
  std::vector<Point2> p(k);
  for (int i = 0; i < k; ++i) p[i] = {V(corner[i], u), flip * V(corner[i], v)};

  std::vector<int> prev(k), next(k);
  for (int i = 0; i < k; ++i) {
    prev[i] = (i + k - 1) % k;
    next[i] = (i + 1) % k;
  }
  auto is_ear = [&](int i) {
    const int a = prev[i], c = next[i];
    if (!(Cross(p[a], p[i], p[c]) > 0)) return false;
    for (int j = next[c]; j != a; j = next[j])
      if (InTriangle(p[j], p[a], p[i], p[c])) return false;
    return true;
  };
  std::vector<char> ear(k);
  for (int i = 0; i < k; ++i) ear[i] = is_ear(i);
  int remaining = k, current = 0;
  while (remaining > 3) {
    int chosen = -1;
    for (int step = 0, i = current; step < remaining; ++step, i = next[i])
      if (ear[i]) {
        chosen = i;
        break;
      }
    if (chosen < 0) {  // no ear: clip the most convex corner so that the loop ends
      double best = -INFINITY;
      for (int step = 0, i = current; step < remaining; ++step, i = next[i]) {
        const double turn = Cross(p[prev[i]], p[i], p[next[i]]);
        if (turn > best || chosen < 0) {
          best = turn;
          chosen = i;
        }
      }
    }
    const int a = prev[chosen], c = next[chosen];
    out->push_back({corner[a], corner[chosen], corner[c]});
    next[a] = c;
    prev[c] = a;
    --remaining;
    current = c;
    ear[a] = is_ear(a);
    ear[c] = is_ear(c);
  }
  out->push_back({corner[prev[current]], corner[current], corner[next[current]]});
}

}  // namespace

Faces TriangulatePolygons(const PolygonFaces& faces, const Positions& V, int* polygons) {
  std::vector<std::array<int, 3>> triangles;
  triangles.reserve(faces.corners.size() - 2 * static_cast<size_t>(faces.face_count()));
  int polygon_count = 0;
  for (int f = 0; f < faces.face_count(); ++f) {
    const int* corner = faces.corners.data() + faces.starts[f];
    const int k = faces.size(f);
    SUBFLOW_CHECK(k >= 3, "face " + std::to_string(f) + " has fewer than 3 corners");
    if (k == 3) {
      triangles.push_back({corner[0], corner[1], corner[2]});
      continue;
    }
    ++polygon_count;
    ClipEars(corner, k, V, &triangles);
  }
  if (polygons) *polygons = polygon_count;
  Faces F(static_cast<Eigen::Index>(triangles.size()), 3);
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) F(static_cast<Eigen::Index>(t), k) = triangles[t][k];
  return F;
}

}  // namespace subflow::geometry
