// The sparse linear operators of Loop subdivision on one level of a mesh, built from its
// connectivity alone (MeshTopology). LoopHierarchy builds them once per level; they are
// free functions so tests and other stages can apply them to any topology.
//
// All operators act on control points stored as rows (Positions, #V×3): result = M c.
// Notation: a vertex v of valence K has the ordered 1-ring r_0 … r_{K−1}
// (MeshTopology::Ring, counter-clockwise seen from outside). A boundary vertex has
// k = K − 1 faces; r_0 and r_k are its two boundary neighbours.
#pragma once

#include <array>

#include <Eigen/Sparse>

#include "geometry/mesh_topology.h"
#include "geometry/point_stencil.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Row-major, so that M * c (c #V×3 row-major) streams rows of M and rows of c.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// y = M x for points x (#cols(M)×3): one pass over M's non-zeros accumulating the three
// coordinates together (Eigen's generic sparse × dense product makes one pass per column).
// This is the hot-path product of refinement, limit masks and synthesis. `y` must not
// alias `x`.
void MultiplyPoints(const SparseMatrix& matrix, const Positions& x, Positions* y);
Positions MultiplyPoints(const SparseMatrix& matrix, const Positions& x);

// Refinement C (method eq. 10): (#V + #E) × #V. Row v < #V is the even vertex v, row
// #V + e the odd vertex inserted on edge e (MeshTopology edge order). Rules (weights in
// loop_weights.h), as in CGAL::Subdivision_method_3::Loop_subdivision:
//   interior even  (1 − α(K)) c(v) + (α(K)/K) Σ_k c(r_k)
//   boundary even  3/4 c(v) + 1/8 (c(r_0) + c(r_k))           (cubic B-spline crease)
//   interior odd   3/8 (c(a) + c(b)) + 1/8 (c(o) + c(o'))   a, b the edge's ends,
//                                                           o, o' the opposite vertices
//   boundary odd   1/2 (c(a) + c(b))
// Every vertex must be referenced by a face (throws subflow::Error otherwise).
SparseMatrix LoopRefinementMatrix(const MeshTopology& topology);

// Umbrella Laplacian (method eq. 16), #V × #V: (L c)(v) = c(v) − mean of its neighbours.
// Interior vertices average their whole 1-ring; boundary vertices average their two
// boundary neighbours only, so the boundary is smoothed as a curve and does not slide
// into the surface.
SparseMatrix UmbrellaLaplacian(const MeshTopology& topology);

// Taubin's non-shrinking smoothing (method eq. 17), #V × #V:
//   H = (I − µL)(I − λL),  λ > 0 > µ, |µ| > λ.
// (I − λL) moves each vertex a fraction λ towards the mean of its neighbours (shrinks);
// (I − µL) moves it −µ away (inflates). Both factors are polynomials in L, so they commute
// and H = I − (λ + µ) L + λµ L²; the shrinking factor is conventionally applied first.
struct TaubinParameters {
  double lambda = 0.6324;  // shrinking step (Taubin 1995; the method's choice)
  double mu = -0.6364;     // inflating step; pass-band k_PB = 1/λ + 1/µ ≈ 0.01
};
SparseMatrix TaubinSmoothingMatrix(const MeshTopology& topology,
                                   const TaubinParameters& parameters = {});

// Limit positions, #V × #V: the point of the limit surface at each vertex.
//   interior  s(v) = (ω c(v) + Σ_k c(r_k)) / (ω + K),  ω = 3/(8β), β = α(K)/K
//             (regular K = 6: 1/2 c(v) + 1/12 Σ c(r_k))
//   boundary  s(v) = 2/3 c(v) + 1/6 (c(r_0) + c(r_k))   (the cubic B-spline limit)
// These are the left eigenvectors of the local subdivision matrix for eigenvalue 1.
SparseMatrix LoopLimitPositionMatrix(const MeshTopology& topology);

// Limit tangents, two #V × #V matrices [T1, T2]: left eigenvectors of the local
// subdivision matrix for its subdominant eigenvalues, so T1 c and T2 c span the tangent
// plane of the limit surface at each vertex, and n = T1 c × T2 c points out of the
// surface for counter-clockwise faces.
//   interior  T1: Σ_j cos(2πj/K) c(r_j),  T2: Σ_j sin(2πj/K) c(r_j)
//             (eigenvalue 3/8 + cos(2π/K)/4 for both)
//   boundary  T1 (along the boundary): c(r_0) − c(r_k)          (eigenvalue 1/2)
//             T2 (across, into the surface):
//               k = 1: c(r_0) + c(r_1) − 2 c(v)                  (eigenvalue 1/4)
//               k ≥ 2: b c(v) + a (c(r_0) + c(r_k)) + Σ_{j=1}^{k−1} sin(jθ) c(r_j),
//                      θ = π/k, a = −cos θ (1 + cos θ) / (sin θ (1 + 2 cos θ)),
//                      b = −2a − cot(θ/2)          (eigenvalue 3/8 + cos(θ)/4)
//             For k = 2 and k = 3 this is Hoppe et al. 1994's mask (c(r_1) − c(v);
//             −c(r_0) + 2c(r_1) + 2c(r_2) − c(r_3) − 2c(v)); for k ≥ 4 Hoppe's mask is
//             not an eigenvector of these (CGAL's) boundary rules, this one is.
// The scale of T1, T2 is arbitrary; only their directions carry meaning.
std::array<SparseMatrix, 2> LoopLimitTangentMatrices(const MeshTopology& topology);

// The same operators in the compact hot-path form (point_stencil.h): C with one channel;
// [T1, T2] with two channels, entries in ring order (boundary vertices: v, r_0 … r_k).
// In the tangent stencil, interior vertices of valence K have pattern key K (so key 6 =
// regular vertices, weights cos/sin(2πj/6)).
PointStencil LoopRefinementStencil(const MeshTopology& topology);
PointStencil LoopLimitTangentStencil(const MeshTopology& topology);

}  // namespace subflow::geometry
