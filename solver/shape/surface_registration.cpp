#include "solver/shape/surface_registration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/mean_edge_length.h"
#include "geometry/vertex_normals.h"
#include "solver/shape/hierarchy_fit.h"

namespace subflow::solver {

using geometry::Positions;

void SurfaceRegistrationOptions::Check() const {
  if (iterations < 0 || iterations > 100)
    ThrowError("surface registration options", "iterations", "expected 0..100");
  if (!(stiffness_start > 0.0 && stiffness_end > 0.0 && std::isfinite(stiffness_start) &&
        std::isfinite(stiffness_end)))
    ThrowError("surface registration options", "stiffness_start / stiffness_end", "expected finite values > 0");
  if (!(point_weight >= 0.0 && point_weight <= 1e3))
    ThrowError("surface registration options", "point_weight", "expected a value in [0, 1000]");
  if (!(max_distance_edges > 0.0 && max_distance_edges <= 1e3))
    ThrowError("surface registration options", "max_distance_edges", "expected a value in (0, 1000]");
  if (!(min_start_distance_edges >= 0.0 && min_start_distance_edges <= 1e3))
    ThrowError("surface registration options", "min_start_distance_edges", "expected a value in [0, 1000]");
  if (!(min_normal_cosine >= -1.0 && min_normal_cosine <= 1.0))
    ThrowError("surface registration options", "min_normal_cosine", "expected a value in [−1, 1]");
}

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;  // column-major: a block's 3 rows are contiguous
using Triplets = std::vector<Eigen::Triplet<double>>;

constexpr double kDamping = 1e-4;   // δ of the header
constexpr double kConverged = 1e-2;  // of the correspondence distance

// Where the 3×3 block (v, w) of the normal equations sits in the values of the fixed
// pattern: the index of entry (3v, 3w + c) for c = 0, 1, 2 (rows 3v + r follow it).
using BlockIndex = std::array<int, 3>;

BlockIndex IndexOf(const SparseMatrix& pattern, int v, int w) {
  BlockIndex index;
  for (int c = 0; c < 3; ++c) {
    const int column = 3 * w + c;
    const int* begin = pattern.innerIndexPtr() + pattern.outerIndexPtr()[column];
    const int* end = pattern.innerIndexPtr() + pattern.outerIndexPtr()[column + 1];
    const int* row = std::lower_bound(begin, end, 3 * v);
    index[c] = static_cast<int>(row - pattern.innerIndexPtr());
  }
  return index;
}

void AddBlock(const BlockIndex& index, const Eigen::Matrix3d& block, double* values) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) values[index[c] + r] += block(r, c);
}

// What the iterations read of the (fixed) target: its face normals, and its vertices with
// their normals, every k-th so that there are about `wanted` of them (the hull's vertices
// are denser than the registration needs).
struct TargetSample {
  Positions face_normals, points, normals;
  TargetSample(const geometry::TriangleMesh& target, Eigen::Index wanted)
      : face_normals(geometry::FaceNormals(target.V, target.F)) {
    const Positions all_normals = geometry::VertexNormals(target.V, target.F);
    const Eigen::Index stride = std::max<Eigen::Index>(1, (target.V.rows() + wanted - 1) / std::max<Eigen::Index>(1, wanted));
    const Eigen::Index count = (target.V.rows() + stride - 1) / stride;
    points.resize(count, 3);
    normals.resize(count, 3);
    for (Eigen::Index j = 0; j < count; ++j) {
      points.row(j) = target.V.row(j * stride);
      normals.row(j) = all_normals.row(j * stride);
    }
  }
};

struct Distances {
  double surface = 0.0;  // mean, limit points → target
  double target = 0.0;   // mean, target samples → limit mesh
  double reachable = 0.0;  // mean over the samples within the correspondence distance
};

// Per limit point: the 3×3 block B and vector B·p of its data terms (w [n nᵀ + β I]).
struct PointTerms {
  std::vector<Eigen::Matrix3d> block;
  std::vector<Eigen::Vector3d> rhs;
  explicit PointTerms(Eigen::Index points) : block(points, Eigen::Matrix3d::Zero()), rhs(points, Eigen::Vector3d::Zero()) {}
  void Add(Eigen::Index point, const Eigen::Vector3d& target, const Eigen::Vector3d& n, double w, double beta) {
    const Eigen::Matrix3d B = w * (n * n.transpose() + beta * Eigen::Matrix3d::Identity());
    block[point] += B;
    rhs[point] += B * target;
  }
};

// The correspondences of one iteration (or, with `terms` null, only the distances).
Distances Correspond(const geometry::TriangleMesh& limit_mesh, const geometry::ClosestPointTree& target,
                     const TargetSample& sample, const SurfaceRegistrationOptions& options, double max_distance,
                     PointTerms* terms) {
  Distances distances;
  const Positions limit_normals = terms ? geometry::VertexNormals(limit_mesh.V, limit_mesh.F) : Positions();
  const std::vector<geometry::SurfacePoint> forward = target.ClosestPoints(limit_mesh.V);
  const double forward_weight = 1.0 / std::max<Eigen::Index>(1, limit_mesh.V.rows());
  for (Eigen::Index i = 0; i < limit_mesh.V.rows(); ++i) {
    const geometry::SurfacePoint& hit = forward[i];
    distances.surface += hit.distance * forward_weight;
    if (!terms || hit.face < 0 || hit.distance > max_distance) continue;
    const Eigen::Vector3d n = sample.face_normals.row(hit.face).transpose();
    if (n.dot(limit_normals.row(i).transpose()) < options.min_normal_cosine) continue;
    terms->Add(i, hit.point, n, forward_weight, options.point_weight);
  }

  const geometry::ClosestPointTree surface(limit_mesh, "registered surface");
  const Positions surface_normals = terms ? geometry::FaceNormals(limit_mesh.V, limit_mesh.F) : Positions();
  const std::vector<geometry::SurfacePoint> backward = surface.ClosestPoints(sample.points);
  int reachable = 0;
  const double backward_weight = 1.0 / std::max<Eigen::Index>(1, sample.points.rows());
  for (Eigen::Index j = 0; j < sample.points.rows(); ++j) {
    const geometry::SurfacePoint& hit = backward[j];
    distances.target += hit.distance * backward_weight;
    if (hit.distance <= max_distance) distances.reachable += hit.distance, ++reachable;
    if (!terms || hit.face < 0 || hit.distance > max_distance) continue;
    const Eigen::Vector3d n = sample.normals.row(j).transpose();
    if (n.dot(surface_normals.row(hit.face).transpose()) < options.min_normal_cosine) continue;
    const Eigen::Vector3d b(1.0 - hit.barycentric.x() - hit.barycentric.y(), hit.barycentric.x(),
                            hit.barycentric.y());
    Eigen::Index corner = 0;
    b.maxCoeff(&corner);
    terms->Add(limit_mesh.F(hit.face, corner), sample.points.row(j).transpose(), n, backward_weight,
               options.point_weight);
  }
  if (reachable > 0) distances.reachable /= reachable;
  return distances;
}

}  // namespace

struct SurfaceRegistration::Impl {
  const geometry::LoopHierarchy& hierarchy;
  SurfaceRegistrationOptions options;
  double edge_length = 0.0;  // ≤ 0: each start's own
  int evaluation_level = 0;
  geometry::SparseMatrix L;  // limit points of the evaluation level from base control points
  SparseMatrix pattern;      // the normal equations' pattern (3V × 3V, values 0)
  // Per limit point i, the blocks (v, w) of the pairs of entries of its row of L, from
  // pairs[offset[i]] on: (a, b) for a, then b, in the row's order.
  std::vector<int> offset;
  std::vector<BlockIndex> pairs;
  // Stiffness (per unit α) and damping, in the pattern's values; the edges' blocks.
  std::vector<BlockIndex> edge_blocks;  // per edge: (a,a), (b,b), (a,b), (b,a)
  std::vector<BlockIndex> diagonal;     // per vertex: (v,v)

  Impl(const geometry::LoopHierarchy& h, const SurfaceRegistrationOptions& o, double edge)
      : hierarchy(h), options(o), edge_length(edge) {
    options.Check();
    evaluation_level = std::min(1, hierarchy.finest_level());
    L = hierarchy.LimitPositions(evaluation_level);
    for (int level = evaluation_level - 1; level >= 0; --level) L = L * hierarchy.Refinement(level);
    const geometry::MeshTopology& topology = hierarchy.Topology(0);
    const int V = hierarchy.VertexCount(0);

    // The pattern of the blocks (V × V) first, then each block's 9 entries: the pairs of
    // L's rows repeat blocks many times over.
    Triplets blocks;
    for (int i = 0; i < L.outerSize(); ++i)
      for (geometry::SparseMatrix::InnerIterator a(L, i); a; ++a)
        for (geometry::SparseMatrix::InnerIterator b(L, i); b; ++b) blocks.emplace_back(a.col(), b.col(), 0.0);
    for (int e = 0; e < topology.edge_count(); ++e) {
      blocks.emplace_back(topology.EdgeVertex(e, 0), topology.EdgeVertex(e, 1), 0.0);
      blocks.emplace_back(topology.EdgeVertex(e, 1), topology.EdgeVertex(e, 0), 0.0);
    }
    for (int v = 0; v < V; ++v) blocks.emplace_back(v, v, 0.0);
    SparseMatrix block_pattern(V, V);
    block_pattern.setFromTriplets(blocks.begin(), blocks.end());
    Triplets triplets;
    triplets.reserve(9 * block_pattern.nonZeros());
    for (int w = 0; w < block_pattern.outerSize(); ++w)
      for (SparseMatrix::InnerIterator it(block_pattern, w); it; ++it)
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) triplets.emplace_back(3 * it.row() + r, 3 * w + c, 0.0);
    pattern.resize(3 * V, 3 * V);
    pattern.setFromTriplets(triplets.begin(), triplets.end());
    pattern.makeCompressed();

    offset.assign(L.rows() + 1, 0);
    for (int i = 0; i < L.outerSize(); ++i) {
      offset[i] = static_cast<int>(pairs.size());
      for (geometry::SparseMatrix::InnerIterator a(L, i); a; ++a)
        for (geometry::SparseMatrix::InnerIterator b(L, i); b; ++b)
          pairs.push_back(IndexOf(pattern, static_cast<int>(a.col()), static_cast<int>(b.col())));
    }
    offset[L.rows()] = static_cast<int>(pairs.size());
    for (int e = 0; e < topology.edge_count(); ++e) {
      const int a = topology.EdgeVertex(e, 0), b = topology.EdgeVertex(e, 1);
      for (const auto& [v, w] : {std::pair{a, a}, std::pair{b, b}, std::pair{a, b}, std::pair{b, a}})
        edge_blocks.push_back(IndexOf(pattern, v, w));
    }
    for (int v = 0; v < V; ++v) diagonal.push_back(IndexOf(pattern, v, v));
  }

  // The normal equations H c = g at stiffness α.
  void Assemble(const PointTerms& terms, const Positions& start, double alpha, SparseMatrix* H,
                Eigen::VectorXd* g) const {
    *H = pattern;
    double* values = H->valuePtr();
    *g = Eigen::VectorXd::Zero(pattern.rows());
    for (int i = 0; i < L.outerSize(); ++i) {
      if (terms.block[i].isZero(0.0)) continue;
      const BlockIndex* pair = pairs.data() + offset[i];  // in the order they were built
      for (geometry::SparseMatrix::InnerIterator ia(L, i); ia; ++ia) {
        g->segment<3>(3 * ia.col()) += ia.value() * terms.rhs[i];
        for (geometry::SparseMatrix::InnerIterator ib(L, i); ib; ++ib)
          AddBlock(*pair++, (ia.value() * ib.value()) * terms.block[i], values);
      }
    }
    const geometry::MeshTopology& topology = hierarchy.Topology(0);
    const double w = alpha / std::max(1, topology.edge_count());
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    for (int e = 0; e < topology.edge_count(); ++e) {
      const int a = topology.EdgeVertex(e, 0), b = topology.EdgeVertex(e, 1);
      AddBlock(edge_blocks[4 * e], w * I, values);
      AddBlock(edge_blocks[4 * e + 1], w * I, values);
      AddBlock(edge_blocks[4 * e + 2], -w * I, values);
      AddBlock(edge_blocks[4 * e + 3], -w * I, values);
      const Eigen::Vector3d d = (start.row(a) - start.row(b)).transpose();
      g->segment<3>(3 * a) += w * d;
      g->segment<3>(3 * b) -= w * d;
    }
    const double damping = kDamping / std::max<Eigen::Index>(1, start.rows());
    for (Eigen::Index v = 0; v < start.rows(); ++v) {
      AddBlock(diagonal[v], damping * I, values);
      g->segment<3>(3 * v) += damping * start.row(v).transpose();
    }
  }
};

SurfaceRegistration::SurfaceRegistration(const geometry::LoopHierarchy& hierarchy,
                                         const SurfaceRegistrationOptions& options, double edge_length)
    : impl_(std::make_unique<const Impl>(hierarchy, options, edge_length)) {}

SurfaceRegistration::~SurfaceRegistration() = default;

Positions SurfaceRegistration::Register(const Positions& base_control_points, const geometry::ClosestPointTree& target,
                                        SurfaceRegistrationReport* report) const {
  const Stopwatch start;
  const Impl& impl = *impl_;
  const geometry::LoopHierarchy& hierarchy = impl.hierarchy;
  CheckBaseControlPoints(hierarchy, base_control_points, "surface registration");

  const SurfaceRegistrationOptions& options = impl.options;
  geometry::TriangleMesh limit_mesh{impl.L * base_control_points, hierarchy.LevelFaces(impl.evaluation_level)};
  const double mean_edge = impl.edge_length > 0.0
                               ? impl.edge_length
                               : geometry::MeanEdgeLength(hierarchy.Topology(0), base_control_points);
  const double max_distance = options.max_distance_edges * mean_edge;
  const TargetSample sample(target.mesh(), impl.L.rows());

  SurfaceRegistrationReport local;
  SurfaceRegistrationReport& out = report ? *report : local;
  out = SurfaceRegistrationReport();
  Positions control = base_control_points;
  const Distances before = Correspond(limit_mesh, target, sample, options, max_distance, nullptr);
  out.mean_surface_distance_before = before.surface;
  out.mean_target_distance_before = before.target;
  out.reachable_target_distance_before = before.reachable;
  const bool needed = before.reachable > options.min_start_distance_edges * mean_edge;
  const int iterations = options.enabled && needed ? options.iterations : 0;
  Eigen::SimplicialLDLT<SparseMatrix> solver;
  if (iterations > 0) solver.analyzePattern(impl.pattern);
  for (int k = 0; k < iterations; ++k) {
    const double t = iterations > 1 ? static_cast<double>(k) / (iterations - 1) : 1.0;
    const double alpha = options.stiffness_start * std::pow(options.stiffness_end / options.stiffness_start, t);
    PointTerms terms(impl.L.rows());
    Correspond(limit_mesh, target, sample, options, max_distance, &terms);
    SparseMatrix H;
    Eigen::VectorXd g;
    impl.Assemble(terms, base_control_points, alpha, &H, &g);
    solver.factorize(H);
    if (solver.info() != Eigen::Success) break;  // keep the last solution
    const Eigen::VectorXd x = solver.solve(g);
    if (!x.allFinite()) break;
    const Positions next = Eigen::Map<const Positions>(x.data(), x.size() / 3, 3);
    const double largest_step = (next - control).rowwise().norm().maxCoeff();
    control = next;
    limit_mesh.V = impl.L * control;
    out.iterations = k + 1;
    if (largest_step < kConverged * max_distance) break;
  }
  out.applied = out.iterations > 0;
  const Distances after =
      out.applied ? Correspond(limit_mesh, target, sample, options, max_distance, nullptr) : before;
  out.mean_surface_distance_after = after.surface;
  out.mean_target_distance_after = after.target;
  out.seconds = start.Seconds();
  return control;
}

Positions RegisterToSurface(const geometry::LoopHierarchy& hierarchy, const Positions& base_control_points,
                            const geometry::ClosestPointTree& target, const SurfaceRegistrationOptions& options,
                            SurfaceRegistrationReport* report) {
  return SurfaceRegistration(hierarchy, options).Register(base_control_points, target, report);
}

}  // namespace subflow::solver
