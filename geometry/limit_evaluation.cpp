#include "geometry/limit_evaluation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/loop_box_spline.h"
#include "geometry/loop_local_patch.h"

namespace subflow::geometry {
namespace {

using loop_patch::LocalPatch;
using loop_patch::LocalWeights;

constexpr double kParameterTolerance = 1e-12;
// Local refinement halves the distance to the nearest irregular corner per level; a
// double reaches it after at most 1074 + 53 halvings.
constexpr int kMaxRefinementDepth = 1200;

bool IsInteriorRegular(const MeshTopology& topology, int v) {
  return !topology.IsBoundaryVertex(v) && topology.Valence(v) == 6;
}

// Jacobian d(u', v')/d(u, v) of a rotation of the corners (loop_patch::RotatePatch).
Eigen::Matrix2d RotationJacobian(int rotation) {
  Eigen::Matrix2d j;
  if (rotation == 0) j.setIdentity();
  if (rotation == 1) j << 0, 1, -1, -1;  // (u', v') = (v, 1 − u − v)
  if (rotation == 2) j << -1, -1, 1, 0;  // (u', v') = (1 − u − v, u)
  return j;
}

void RotateParameters(int rotation, double* u, double* v) {
  const double w = 1.0 - *u - *v;
  if (rotation == 1) *u = *v, *v = w;
  if (rotation == 2) *v = *u, *u = w;
}

// The 12 box-spline control points of a regular face (loop_box_spline.h's order).
std::array<int, 12> RegularControlIndices(const MeshTopology& topology, int face) {
  std::array<int, 3> corner;
  for (int k = 0; k < 3; ++k) corner[k] = topology.HalfedgeSource(3 * face + k);
  std::array<int, 12> indices;
  for (int j = 0; j < 12; ++j) {
    const BoxSplineControlSlot slot = kBoxSplineControlSlots[j];
    if (slot.position < 0) {
      indices[j] = corner[slot.ring];
      continue;
    }
    const IndexRange ring = topology.Ring(corner[slot.ring]);
    const int next = corner[(slot.ring + 1) % 3];
    int start = 0;
    while (ring[start] != next) ++start;
    indices[j] = ring[(start + slot.position) % 6];
  }
  return indices;
}

// Evaluation by local refinement (see limit_evaluation.h). Writes weights over
// patch.support (which local refinement never changes).
void EvaluateByRefinement(LocalPatch patch, double u, double v, Eigen::RowVectorXd* position,
                          Eigen::RowVectorXd* du, Eigen::RowVectorXd* dv) {
  // d(local parameters)/d(face parameters) = 2^exponent · jacobian.
  Eigen::Matrix2d jacobian = Eigen::Matrix2d::Identity();
  int exponent = 0;
  const int at_corner = (u == 0 && v == 0) ? 0 : (u == 1 && v == 0) ? 1 : (u == 0 && v == 1) ? 2 : -1;
  std::optional<LocalWeights> weights;
  if (at_corner >= 0 && !loop_patch::IsRegularCorner(patch, at_corner)) {
    weights.emplace(patch.local_count());
    loop_patch::AddIrregularCornerWeights(patch, at_corner, &*weights);
    jacobian = RotationJacobian(at_corner);
  }
  for (int depth = 0; !weights; ++depth) {
    SUBFLOW_CHECK(depth <= kMaxRefinementDepth, "local refinement did not reach a regular patch");
    if (loop_patch::IsRegularPatch(patch)) {
      weights.emplace(patch.local_count());
      loop_patch::AddBoxSplineWeights(patch, u, v, &*weights);
      break;
    }
    int child;
    Eigen::Matrix2d step = Eigen::Matrix2d::Identity();
    if (u + v < 0.5) {
      child = 0, u = 2 * u, v = 2 * v;
    } else if (u >= 0.5) {
      child = 1, u = 2 * u - 1, v = 2 * v;
    } else if (v >= 0.5) {
      child = 2, u = 2 * u, v = 2 * v - 1;
    } else {
      child = 3;
      const double u_child = 2 * u + 2 * v - 1;
      v = 1 - 2 * u, u = u_child;
      step << 1, 1, -1, 0;
    }
    jacobian = step * jacobian;
    ++exponent;
    patch = loop_patch::RefinePatch(patch, child);
  }
  *position = patch.reference + weights->position.transpose() * patch.offsets;
  // ∂/∂u = 2^e (J₀₀ ∂/∂u' + J₁₀ ∂/∂v'); the derivative weights sum to 0, so only offsets.
  const Eigen::VectorXd local_du = jacobian(0, 0) * weights->du + jacobian(1, 0) * weights->dv;
  const Eigen::VectorXd local_dv = jacobian(0, 1) * weights->du + jacobian(1, 1) * weights->dv;
  *du = local_du.transpose() * patch.offsets;
  *dv = local_dv.transpose() * patch.offsets;
  for (Eigen::Index i = 0; i < du->size(); ++i) {
    (*du)[i] = std::ldexp((*du)[i], exponent);
    (*dv)[i] = std::ldexp((*dv)[i], exponent);
  }
}

}  // namespace

void LimitStencil::Clear() {
  vertices.clear();
  position.clear();
  du.clear();
  dv.clear();
}

Eigen::RowVector3d LimitPoint::Normal() const {
  const Eigen::RowVector3d n = du.cross(dv);
  const double length = n.norm();
  return length > 0 ? Eigen::RowVector3d(n / length) : Eigen::RowVector3d::Zero();
}

LoopLimitEvaluator::LoopLimitEvaluator(const MeshTopology& topology,
                                       const LimitEvaluatorOptions& options)
    : topology_(&topology) {
  for (int v = 0; v < topology.vertex_count(); ++v)
    if (topology.Valence(v) > 0 && !topology.IsBoundaryVertex(v) && topology.Valence(v) < 3)
      ThrowError("limit evaluation", "vertex " + std::to_string(v),
                 "interior vertex of valence " + std::to_string(topology.Valence(v)) +
                     " (Loop subdivision needs valence >= 3)");

  std::map<std::vector<int>, int> stam_patch_of_structure;  // −1: not a Stam patch
  faces_.resize(topology.face_count());
  for (int f = 0; f < topology.face_count(); ++f) {
    FaceRecord& record = faces_[f];
    record.offset = static_cast<int>(indices_.size());
    std::array<bool, 3> regular;
    int irregular_interior = -1, irregular_count = 0;
    bool any_boundary = false;
    for (int k = 0; k < 3; ++k) {
      const int v = topology.HalfedgeSource(3 * f + k);
      regular[k] = IsInteriorRegular(topology, v);
      any_boundary |= topology.IsBoundaryVertex(v);
      if (!regular[k]) ++irregular_count, irregular_interior = k;
    }
    if (irregular_count == 0) {
      record.kind = LimitPatchKind::kRegular;
      const std::array<int, 12> indices = RegularControlIndices(topology, f);
      indices_.insert(indices_.end(), indices.begin(), indices.end());
      continue;
    }
    if (!options.use_stam_patches || irregular_count != 1 || any_boundary) continue;
    const LocalPatch rotated =
        loop_patch::RotatePatch(loop_patch::PatchAroundFace(topology, f), irregular_interior);
    std::vector<int> structure, order;
    const LocalPatch canonical = loop_patch::CanonicalPatch(rotated, &structure, &order);
    auto [it, inserted] = stam_patch_of_structure.emplace(structure, -1);
    if (inserted) {
      loop_patch::StamPatch stam;
      if (loop_patch::BuildStamPatch(canonical, &stam)) {
        it->second = static_cast<int>(stam_patches_.size());
        stam_patches_.push_back(std::move(stam));
      }
    }
    if (it->second < 0) continue;
    record.kind = LimitPatchKind::kStam;
    record.rotation = irregular_interior;
    record.stam_patch = it->second;
    for (const int local : order) indices_.push_back(rotated.support[local]);
  }
}

void LoopLimitEvaluator::CheckSample(int face, double* u, double* v) const {
  if (face < 0 || face >= topology_->face_count())
    ThrowError("limit evaluation", "face " + std::to_string(face),
               "out of range [0, " + std::to_string(topology_->face_count()) + ")");
  const double sum = *u + *v;
  if (!(*u >= 0.0 && *v >= 0.0 && sum <= 1.0 + kParameterTolerance))
    ThrowError("limit evaluation", "face " + std::to_string(face),
               "barycentric parameters (u, v) = (" + std::to_string(*u) + ", " +
                   std::to_string(*v) + ") outside the triangle u, v >= 0, u + v <= 1");
  if (sum > 1.0) *u /= sum, *v /= sum;
}

void LoopLimitEvaluator::Stencil(int face, double u, double v, LimitStencil* stencil) const {
  CheckSample(face, &u, &v);
  stencil->Clear();
  const FaceRecord& record = faces_[face];
  if (record.kind == LimitPatchKind::kRegular) {
    std::array<double, 12> b, b_du, b_dv;
    LoopBoxSplineBasis(u, v, &b, &b_du, &b_dv);
    stencil->vertices.assign(indices_.begin() + record.offset,
                             indices_.begin() + record.offset + 12);
    stencil->position.assign(b.begin(), b.end());
    stencil->du.assign(b_du.begin(), b_du.end());
    stencil->dv.assign(b_dv.begin(), b_dv.end());
    return;
  }
  Eigen::RowVectorXd position, du, dv;
  if (record.kind == LimitPatchKind::kStam) {
    const loop_patch::StamPatch& patch = stam_patches_[record.stam_patch];
    double u_rotated = u, v_rotated = v;
    RotateParameters(record.rotation, &u_rotated, &v_rotated);
    Eigen::RowVectorXd du_rotated, dv_rotated;
    loop_patch::StamPatchWeights(patch, u_rotated, v_rotated, &position, &du_rotated, &dv_rotated);
    const Eigen::Matrix2d j = RotationJacobian(record.rotation);
    du = j(0, 0) * du_rotated + j(1, 0) * dv_rotated;
    dv = j(0, 1) * du_rotated + j(1, 1) * dv_rotated;
    const int k = static_cast<int>(position.size());
    stencil->vertices.assign(indices_.begin() + record.offset,
                             indices_.begin() + record.offset + k);
  } else {
    const LocalPatch patch = loop_patch::PatchAroundFace(*topology_, face);
    EvaluateByRefinement(patch, u, v, &position, &du, &dv);
    stencil->vertices = patch.support;
  }
  stencil->position.assign(position.data(), position.data() + position.size());
  stencil->du.assign(du.data(), du.data() + du.size());
  stencil->dv.assign(dv.data(), dv.data() + dv.size());
}

LimitStencil LoopLimitEvaluator::Stencil(int face, double u, double v) const {
  LimitStencil stencil;
  Stencil(face, u, v, &stencil);
  return stencil;
}

LimitPoint LoopLimitEvaluator::Evaluate(int face, double u, double v,
                                        const Positions& control) const {
  if (control.rows() != topology_->vertex_count())
    ThrowError("limit evaluation", "control points",
               std::to_string(control.rows()) + " rows, expected " +
                   std::to_string(topology_->vertex_count()) + " (one per mesh vertex)");
  LimitStencil stencil;
  Stencil(face, u, v, &stencil);
  LimitPoint point;
  for (int i = 0; i < stencil.size(); ++i) {
    const auto c = control.row(stencil.vertices[i]);
    point.position += stencil.position[i] * c;
    point.du += stencil.du[i] * c;
    point.dv += stencil.dv[i] * c;
  }
  return point;
}

SparseMatrix LoopLimitEvaluator::LimitMatrix(const std::vector<FaceSample>& samples,
                                             SparseMatrix* d_du, SparseMatrix* d_dv) const {
  const int rows = static_cast<int>(samples.size());
  const int cols = topology_->vertex_count();
  // Rows are computed in parallel chunks, each into its own buffers, then concatenated.
  constexpr int kChunk = 512;
  const int chunk_count = (rows + kChunk - 1) / kChunk;
  struct Chunk {
    std::vector<int> row_size, columns;
    std::array<std::vector<double>, 3> values;
  };
  std::vector<Chunk> chunks(chunk_count);
  tbb::parallel_for(tbb::blocked_range<int>(0, chunk_count), [&](const tbb::blocked_range<int>& r) {
    LimitStencil stencil;
    std::vector<int> order;
    for (int c = r.begin(); c < r.end(); ++c) {
      Chunk& chunk = chunks[c];
      for (int row = c * kChunk; row < std::min(rows, (c + 1) * kChunk); ++row) {
        const FaceSample& s = samples[row];
        Stencil(s.face, s.u, s.v, &stencil);
        order.resize(stencil.size());
        for (int i = 0; i < stencil.size(); ++i) order[i] = i;
        std::sort(order.begin(), order.end(),
                  [&](int a, int b) { return stencil.vertices[a] < stencil.vertices[b]; });
        int size = 0;
        for (int i = 0; i < stencil.size(); ++i) {
          const int k = order[i];
          if (size > 0 && chunk.columns.back() == stencil.vertices[k]) {
            chunk.values[0].back() += stencil.position[k];
            chunk.values[1].back() += stencil.du[k];
            chunk.values[2].back() += stencil.dv[k];
            continue;
          }
          chunk.columns.push_back(stencil.vertices[k]);
          chunk.values[0].push_back(stencil.position[k]);
          chunk.values[1].push_back(stencil.du[k]);
          chunk.values[2].push_back(stencil.dv[k]);
          ++size;
        }
        chunk.row_size.push_back(size);
      }
    }
  });
  size_t nonzeros = 0;
  for (const Chunk& chunk : chunks) nonzeros += chunk.columns.size();
  std::array<SparseMatrix*, 3> outputs = {nullptr, d_du, d_dv};
  SparseMatrix position(rows, cols);
  outputs[0] = &position;
  for (int which = 0; which < 3; ++which) {
    SparseMatrix* out = outputs[which];
    if (!out) continue;
    *out = SparseMatrix(rows, cols);
    out->resizeNonZeros(static_cast<Eigen::Index>(nonzeros));
    int* outer = out->outerIndexPtr();
    int* inner = out->innerIndexPtr();
    double* value = out->valuePtr();
    int row = 0, offset = 0;
    outer[0] = 0;
    for (const Chunk& chunk : chunks) {
      std::copy(chunk.columns.begin(), chunk.columns.end(), inner + offset);
      std::copy(chunk.values[which].begin(), chunk.values[which].end(), value + offset);
      for (const int size : chunk.row_size) {
        offset += size;
        outer[++row] = offset;
      }
    }
  }
  return position;
}

LimitPatchKind LoopLimitEvaluator::PatchKind(int face) const {
  double u = 0, v = 0;
  CheckSample(face, &u, &v);
  return faces_[face].kind;
}

const loop_patch::StamPatch& LoopLimitEvaluator::StamPatchOf(int face) const {
  if (PatchKind(face) != LimitPatchKind::kStam)
    ThrowError("limit evaluation", "face " + std::to_string(face), "not evaluated by Stam's method");
  return stam_patches_[faces_[face].stam_patch];
}

std::vector<int> LoopLimitEvaluator::ControlIndices(int face) const {
  const LimitPatchKind kind = PatchKind(face);
  const int offset = faces_[face].offset;
  const int count = kind == LimitPatchKind::kRegular ? 12
                    : kind == LimitPatchKind::kStam
                        ? static_cast<int>(stam_patches_[faces_[face].stam_patch].limit.size())
                        : 0;
  return std::vector<int>(indices_.begin() + offset, indices_.begin() + offset + count);
}

}  // namespace subflow::geometry
