#include "geometry/loop_local_patch.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "geometry/loop_box_spline.h"
#include "geometry/loop_weights.h"

namespace subflow::geometry::loop_patch {
namespace {

constexpr double kPi = 3.14159265358979323846;

int IndexIn(const std::vector<int>& list, int value) {
  const auto it = std::find(list.begin(), list.end(), value);
  return it == list.end() ? -1 : static_cast<int>(it - list.begin());
}

// A combination of at most three local vertices (a ghost vertex is C + a − b).
struct Combination {
  std::array<int, 3> vertex{};
  std::array<double, 3> weight{};
  int count = 0;
};

Combination Single(int v) { return {{v, 0, 0}, {1.0, 0.0, 0.0}, 1}; }
Combination Ghost(int c, int a, int b) { return {{c, a, b}, {1.0, 1.0, -1.0}, 3}; }

// The 1-ring of corner i as six combinations read counter-clockwise from `start`;
// a regular boundary corner (4 neighbours) is completed by its two ghost vertices.
std::array<Combination, 6> CompletedRing(const LocalPatch& patch, int i, int start) {
  const std::vector<int>& ring = patch.ring[i];
  const int n = static_cast<int>(ring.size());
  std::array<Combination, 6> full;
  for (int k = 0; k < n; ++k) full[k] = Single(ring[k]);
  if (patch.boundary[i]) {
    const int c = patch.corner[i];
    full[4] = Ghost(c, ring[3], ring[2]);
    full[5] = Ghost(c, ring[0], ring[1]);
  }
  const int s = IndexIn(ring, start);
  SUBFLOW_CHECK(s >= 0, "patch corner ring does not contain the next corner");
  std::array<Combination, 6> rotated;
  for (int k = 0; k < 6; ++k) rotated[k] = full[(s + k) % 6];
  return rotated;
}

std::array<Combination, 12> BoxSplineControls(const LocalPatch& patch) {
  SUBFLOW_CHECK(IsRegularPatch(patch), "box-spline evaluation of a patch with an irregular corner");
  std::array<std::array<Combination, 6>, 3> rings;
  for (int i = 0; i < 3; ++i) rings[i] = CompletedRing(patch, i, patch.corner[(i + 1) % 3]);
  std::array<Combination, 12> controls;
  for (int j = 0; j < 12; ++j) {
    const BoxSplineControlSlot slot = kBoxSplineControlSlots[j];
    controls[j] = slot.position < 0 ? Single(patch.corner[slot.ring])
                                    : rings[slot.ring][slot.position];
  }
  return controls;
}

// The refined vertices of a patch: even copies of the corners and odd vertices on every
// edge at a corner, each keyed by the corner it copies or the edge it splits, with its
// stencil over the coarse patch's local vertices (stored flat: few, short stencils).
class Refinement {
 public:
  struct Term {
    int coarse;
    double weight;
  };

  explicit Refinement(const LocalPatch& patch) : patch_(patch) {
    size_t ring_total = 0;
    for (int i = 0; i < 3; ++i) ring_total += patch.ring[i].size();
    keys_.reserve(ring_total + 3);
    begin_.reserve(ring_total + 4);
    terms_.reserve(4 * ring_total + 16);
    begin_.push_back(0);
    for (int i = 0; i < 3; ++i) AddCornerVertices(i);
  }

  int Even(int i) const { return Find(patch_.corner[i], patch_.corner[i]); }
  int Odd(int a, int b) const { return Find(a, b); }

  // The refined ring of the odd vertex on edge (C_a, C_b) of the triangle, whose third
  // corner is C_p (the triangle is (C_a, C_b, C_p) counter-clockwise).
  std::vector<int> EdgeVertexRing(int a, int b, int p, bool* boundary) const {
    const int ca = patch_.corner[a], cb = patch_.corner[b], cp = patch_.corner[p];
    const std::vector<int>& ring = patch_.ring[a];
    const int n = static_cast<int>(ring.size());
    const int j = IndexIn(ring, cb);
    SUBFLOW_CHECK(j >= 0 && j + 1 < n + (patch_.boundary[a] ? 0 : 1) && ring[(j + 1) % n] == cp,
                  "patch corner rings disagree with the triangle");
    *boundary = patch_.boundary[a] && j == 0;
    if (*boundary) return {Even(b), Odd(cb, cp), Odd(ca, cp), Even(a)};
    const int q = ring[(j - 1 + n) % n];
    return {Even(a), Odd(ca, q), Odd(cb, q), Even(b), Odd(cb, cp), Odd(ca, cp)};
  }

  std::vector<int> EvenRing(int i) const {
    std::vector<int> ring;
    ring.reserve(patch_.ring[i].size());
    for (const int r : patch_.ring[i]) ring.push_back(Odd(patch_.corner[i], r));
    return ring;
  }

  const Term* TermsBegin(int id) const { return terms_.data() + begin_[id]; }
  const Term* TermsEnd(int id) const { return terms_.data() + begin_[id + 1]; }

 private:
  static std::pair<int, int> Key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }
  int Find(int a, int b) const {
    const auto it = std::find(keys_.begin(), keys_.end(), Key(a, b));
    SUBFLOW_CHECK(it != keys_.end(), "refined vertex missing from the local patch");
    return static_cast<int>(it - keys_.begin());
  }
  bool Has(int a, int b) const { return std::find(keys_.begin(), keys_.end(), Key(a, b)) != keys_.end(); }
  void Close(int a, int b) {
    keys_.push_back(Key(a, b));
    begin_.push_back(static_cast<int>(terms_.size()));
  }

  void AddCornerVertices(int i) {
    const int c = patch_.corner[i];
    const std::vector<int>& ring = patch_.ring[i];
    const int n = static_cast<int>(ring.size());
    const bool boundary = patch_.boundary[i];
    if (boundary) {
      terms_.insert(terms_.end(), {{c, kLoopBoundaryEvenCenterWeight},
                                   {ring.front(), kLoopBoundaryEvenNeighbourWeight},
                                   {ring.back(), kLoopBoundaryEvenNeighbourWeight}});
    } else {
      const double alpha = LoopAlpha(n);
      terms_.push_back({c, 1.0 - alpha});
      for (const int r : ring) terms_.push_back({r, alpha / n});
    }
    Close(c, c);
    for (int k = 0; k < n; ++k) {
      if (Has(c, ring[k])) continue;
      if (boundary && (k == 0 || k == n - 1))
        terms_.insert(terms_.end(), {{c, kLoopBoundaryOddWeight}, {ring[k], kLoopBoundaryOddWeight}});
      else
        terms_.insert(terms_.end(), {{c, kLoopOddEdgeWeight},
                                     {ring[k], kLoopOddEdgeWeight},
                                     {ring[(k - 1 + n) % n], kLoopOddOppositeWeight},
                                     {ring[(k + 1) % n], kLoopOddOppositeWeight}});
      Close(c, ring[k]);
    }
  }

  const LocalPatch& patch_;
  std::vector<std::pair<int, int>> keys_;  // (a, a): even copy of a; (a < b): odd on edge ab
  std::vector<int> begin_;                 // terms of vertex i: [begin_[i], begin_[i + 1])
  std::vector<Term> terms_;
};

}  // namespace

LocalPatch PatchAroundFace(const MeshTopology& topology, int face) {
  LocalPatch patch;
  auto local = [&patch](int v) {
    const int i = IndexIn(patch.support, v);
    if (i >= 0) return i;
    patch.support.push_back(v);
    return static_cast<int>(patch.support.size()) - 1;
  };
  for (int k = 0; k < 3; ++k) patch.corner[k] = local(topology.HalfedgeSource(3 * face + k));
  for (int k = 0; k < 3; ++k) {
    const int v = patch.support[patch.corner[k]];
    for (const int r : topology.Ring(v)) patch.ring[k].push_back(local(r));
    patch.boundary[k] = topology.IsBoundaryVertex(v);
  }
  const int n = static_cast<int>(patch.support.size());
  patch.reference = Eigen::RowVectorXd::Unit(n, patch.corner[0]);
  patch.offsets = StencilRows::Identity(n, n);
  patch.offsets.col(patch.corner[0]).array() -= 1.0;
  return patch;
}

bool IsRegularCorner(const LocalPatch& patch, int corner) {
  return patch.ring[corner].size() == (patch.boundary[corner] ? 4u : 6u);
}

bool IsRegularPatch(const LocalPatch& patch) {
  return IsRegularCorner(patch, 0) && IsRegularCorner(patch, 1) && IsRegularCorner(patch, 2);
}

LocalPatch RotatePatch(const LocalPatch& patch, int rotation) {
  LocalPatch rotated = patch;
  for (int i = 0; i < 3; ++i) {
    const int from = (i + rotation) % 3;
    rotated.corner[i] = patch.corner[from];
    rotated.ring[i] = patch.ring[from];
    rotated.boundary[i] = patch.boundary[from];
  }
  return rotated;
}

LocalPatch RefinePatch(const LocalPatch& patch, int child) {
  SUBFLOW_CHECK(child >= 0 && child < 4, "child index");
  const Refinement refinement(patch);
  const int m01 = refinement.Odd(patch.corner[0], patch.corner[1]);
  const int m12 = refinement.Odd(patch.corner[1], patch.corner[2]);
  const int m20 = refinement.Odd(patch.corner[2], patch.corner[0]);

  // Corners of the child, each with its refined ring: an even copy (ring index 0-2 of the
  // coarse corner) or an edge vertex (the coarse edge (a, b) with third corner p).
  struct ChildCorner {
    int id;
    int even_of;      // coarse corner index, or −1
    int a, b, p;      // for edge vertices
  };
  const ChildCorner e0{refinement.Even(0), 0, 0, 0, 0}, e1{refinement.Even(1), 1, 0, 0, 0},
      e2{refinement.Even(2), 2, 0, 0, 0};
  const ChildCorner c01{m01, -1, 0, 1, 2}, c12{m12, -1, 1, 2, 0}, c20{m20, -1, 2, 0, 1};
  const std::array<std::array<ChildCorner, 3>, 4> children = {
      {{e0, c01, c20}, {c01, e1, c12}, {c20, c12, e2}, {c01, c12, c20}}};

  LocalPatch refined;
  refined.support = patch.support;
  std::vector<int> new_ids;  // refinement vertex id of each local vertex of the child
  new_ids.reserve(24);
  auto local = [&new_ids](int id) {
    const int i = IndexIn(new_ids, id);
    if (i >= 0) return i;
    new_ids.push_back(id);
    return static_cast<int>(new_ids.size()) - 1;
  };
  for (int i = 0; i < 3; ++i) refined.corner[i] = local(children[child][i].id);
  for (int i = 0; i < 3; ++i) {
    const ChildCorner& c = children[child][i];
    std::vector<int> ring;
    if (c.even_of >= 0) {
      ring = refinement.EvenRing(c.even_of);
      refined.boundary[i] = patch.boundary[c.even_of];
    } else {
      bool boundary = false;
      ring = refinement.EdgeVertexRing(c.a, c.b, c.p, &boundary);
      refined.boundary[i] = boundary;
    }
    for (const int id : ring) refined.ring[i].push_back(local(id));
  }

  const int n = static_cast<int>(new_ids.size());
  refined.offsets.setZero(n, patch.offsets.cols());
  for (int i = 0; i < n; ++i)  // each refined vertex combines 2 to K + 1 coarse ones
    for (auto t = refinement.TermsBegin(new_ids[i]); t != refinement.TermsEnd(new_ids[i]); ++t)
      refined.offsets.row(i) += t->weight * patch.offsets.row(t->coarse);
  // Re-centre on the child's first corner so the offsets scale with the child.
  const Eigen::RowVectorXd shift = refined.offsets.row(refined.corner[0]);
  refined.reference = patch.reference + shift;
  refined.offsets.rowwise() -= shift;
  return refined;
}

LocalPatch CanonicalPatch(const LocalPatch& patch, std::vector<int>* structure,
                          std::vector<int>* order_out) {
  std::vector<int> order = {patch.corner[0]};
  auto append_ring = [&](int i) {
    const std::vector<int>& ring = patch.ring[i];
    const int n = static_cast<int>(ring.size());
    const int start = patch.boundary[i] ? 0 : IndexIn(ring, patch.corner[(i + 1) % 3]);
    for (int k = 0; k < n; ++k)
      if (IndexIn(order, ring[(start + k) % n]) < 0) order.push_back(ring[(start + k) % n]);
  };
  for (int i = 0; i < 3; ++i) append_ring(i);
  for (int v = 0; v < patch.local_count(); ++v)
    if (IndexIn(order, v) < 0) order.push_back(v);

  LocalPatch canonical;
  canonical.support = patch.support;
  canonical.reference = patch.reference;
  canonical.offsets.resize(patch.local_count(), patch.offsets.cols());
  for (int i = 0; i < patch.local_count(); ++i) canonical.offsets.row(i) = patch.offsets.row(order[i]);
  for (int i = 0; i < 3; ++i) {
    canonical.corner[i] = IndexIn(order, patch.corner[i]);
    canonical.boundary[i] = patch.boundary[i];
    for (const int r : patch.ring[i]) canonical.ring[i].push_back(IndexIn(order, r));
  }
  if (structure) {
    structure->clear();
    for (int i = 0; i < 3; ++i) {
      const std::vector<int>& ring = canonical.ring[i];
      const int n = static_cast<int>(ring.size());
      const int start = patch.boundary[i] ? 0 : IndexIn(ring, canonical.corner[(i + 1) % 3]);
      SUBFLOW_CHECK(start >= 0, "patch corner ring does not contain the next corner");
      structure->push_back(canonical.corner[i]);
      structure->push_back(patch.boundary[i] ? 1 : 0);
      structure->push_back(n);
      for (int k = 0; k < n; ++k) structure->push_back(ring[(start + k) % n]);
    }
    structure->push_back(patch.local_count());
  }
  if (order_out) *order_out = order;
  return canonical;
}

void AddBoxSplineWeights(const LocalPatch& patch, double u, double v, LocalWeights* weights) {
  std::array<double, 12> b, b_du, b_dv;
  LoopBoxSplineBasis(u, v, &b, &b_du, &b_dv);
  const std::array<Combination, 12> controls = BoxSplineControls(patch);
  for (int j = 0; j < 12; ++j) {
    const Combination& c = controls[j];
    for (int t = 0; t < c.count; ++t) {
      weights->position[c.vertex[t]] += b[j] * c.weight[t];
      weights->du[c.vertex[t]] += b_du[j] * c.weight[t];
      weights->dv[c.vertex[t]] += b_dv[j] * c.weight[t];
    }
  }
}

Eigen::MatrixXd BoxSplineControlMatrix(const LocalPatch& patch) {
  const std::array<Combination, 12> controls = BoxSplineControls(patch);
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(12, patch.local_count());
  for (int j = 0; j < 12; ++j)
    for (int t = 0; t < controls[j].count; ++t) g(j, controls[j].vertex[t]) += controls[j].weight[t];
  return g;
}

void AddIrregularCornerWeights(const LocalPatch& patch, int corner, LocalWeights* weights) {
  const int c = patch.corner[corner];
  const std::vector<int>& ring = patch.ring[corner];
  const int n = static_cast<int>(ring.size());
  const int j = IndexIn(ring, patch.corner[(corner + 1) % 3]);
  SUBFLOW_CHECK(j >= 0, "patch corner ring does not contain the next corner");
  Eigen::VectorXd& position = weights->position;
  Eigen::VectorXd& du = weights->du;
  Eigen::VectorXd& dv = weights->dv;
  if (!patch.boundary[corner]) {
    // Loop's limit mask (loop_weights.h).
    const LoopLimitWeights limit = LoopInteriorLimitWeights(n);
    position[c] += limit.center;
    for (int k = 0; k < n; ++k) {
      position[ring[k]] += limit.ring;
      du[ring[k]] += 2.0 / n * std::cos(2.0 * kPi * (k - j) / n);
      dv[ring[k]] += 2.0 / n * std::cos(2.0 * kPi * (k - j - 1) / n);
    }
    return;
  }
  // Boundary: the cubic B-spline limit of the boundary curve.
  const int faces = n - 1;
  position[c] += kLoopBoundaryLimitCenterWeight;
  position[ring.front()] += kLoopBoundaryLimitNeighbourWeight;
  position[ring.back()] += kLoopBoundaryLimitNeighbourWeight;
  if (faces == 1) {
    du[ring[0]] += 1.0, du[c] -= 1.0;
    dv[ring[1]] += 1.0, dv[c] -= 1.0;
    return;
  }
  const double theta = kPi / faces;
  const double mu = 3.0 / 8.0 + std::cos(theta) / 4.0;
  double sine_sum = 0.0;
  for (int i = 1; i < faces; ++i) sine_sum += std::sin(i * theta);
  // Left eigenvector (a on c, b on r_0 and r_k, sin(iθ) on r_i) for eigenvalue µ.
  const double b = ((0.75 - mu) * std::sin(theta) - 0.375 * sine_sum) /
                   (8.0 * (0.75 - mu) * (mu - 0.5) + 1.0);
  const double a = 8.0 * (mu - 0.5) * b - std::sin(theta);
  auto add_tangent = [&](int edge, Eigen::VectorXd& out) {
    const double along = std::cos(edge * theta) / 2.0;
    const double across = std::sin(edge * theta) * 2.0 / faces;
    out[ring.front()] += along + across * b;
    out[ring.back()] += -along + across * b;
    out[c] += across * a;
    for (int i = 1; i < faces; ++i) out[ring[i]] += across * std::sin(i * theta);
  };
  add_tangent(j, du);
  add_tangent(j + 1, dv);
}

}  // namespace subflow::geometry::loop_patch
