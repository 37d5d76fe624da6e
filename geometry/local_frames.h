// Local orthonormal frames per vertex (method §3.4, after Hoppe et al. 1994): detail
// vectors are stored in the frame F(v) = (n, r, q) of the limit surface at v so that they
// move with the surface under rigid (and approximately under smooth) motion of the coarse
// levels.
//
//   t1 = (T1 c)(v), t2 = (T2 c)(v)  the Loop limit tangents (loop_operators.h)
//   n  = t1 × t2 / |t1 × t2|        the limit normal, outward for counter-clockwise faces
//   r  = t1 / |t1|                  (t1 ⟂ n already, so this is t1 projected off n)
//   q  = n × r                      so (n, r, q) is right-handed and orthonormal
//
// A detail d(v) = (d_n, d_r, d_q) (a row of a #V×3 matrix) means the world vector
// d_n n + d_r r + d_q q. Because T1 and T2 annihilate constants and are linear, a rigid
// motion x ↦ R x + t of the control points rotates every frame by R.
//
// Degenerate rings (t1 = 0 or t1 ∥ t2, e.g. a collapsed neighbourhood) get the frame
// (n, r, q) = (e_z, e_x, e_y); it is deterministic, so analysis and synthesis stay exact
// inverses, but such details do not follow rigid motions.
#pragma once

#include <Eigen/Core>

#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

struct LocalFrames {
  Positions normal;  // #V×3, unit n per vertex
  Positions r;       // #V×3, unit first tangent
  Positions q;       // #V×3, unit second tangent, n × r

  int vertex_count() const { return static_cast<int>(normal.rows()); }
  // Local (d_n, d_r, d_q) rows → world vectors: row v = d_n n + d_r r + d_q q.
  Positions ToWorld(const Positions& local) const;
  // World vectors → local components: row v = (x·n, x·r, x·q) (the transpose F(v)ᵀ x).
  Positions ToLocal(const Positions& world) const;
};

// One vertex's frame from its two tangents (the degenerate fallback included).
void FrameFromTangents(const Eigen::Vector3d& t1, const Eigen::Vector3d& t2,
                       Eigen::Vector3d* n, Eigen::Vector3d* r, Eigen::Vector3d* q);

// Frames of the limit surface at level `level`'s vertices for control points c
// (#V(level)×3): tangents T1 c, T2 c of the hierarchy's limit tangent masks.
LocalFrames ComputeLocalFrames(const LoopHierarchy& hierarchy, int level,
                               const Positions& control_points);

// The synthesis step (hot path), fused: result = predicted + F d, F the frames of
// `predicted` at `level` and d = `local` (#V(level)×3, rows (d_n, d_r, d_q)). Equivalent to
//   predicted + ComputeLocalFrames(hierarchy, level, predicted).ToWorld(local)
// (same arithmetic) without materializing the frames. `result` must not alias `predicted`.
void AddDetailsInLocalFrames(const LoopHierarchy& hierarchy, int level,
                             const Positions& predicted, const Positions& local,
                             Positions* result);

// The whole synthesis step into `level` ≥ 1 in two passes (even, then odd vertices):
//   result = p + F d,  p = C(level − 1) coarse,  F the frames of p at `level`,
// d = `local`. Equal to RefinementStencil(level − 1).Apply then AddDetailsInLocalFrames up
// to rounding (p itself is computed with Apply's sums): the tangents of p come from the
// coarse points through the tables of hierarchy.SynthesisPlanOf(level), so the odd rows of
// p are never stored or gathered. `result` must not alias the inputs.
//
// The step runs in one of two instruction sets, with the same formulas: the x86-64
// baseline (SSE2), and AVX2 with fused multiply-adds, which rounds the frames and F d
// differently by a few ulps (p is rounded as Apply rounds it in both). kBest takes AVX2+FMA
// when the CPU has both; asking for kAvx2Fma on a CPU without them throws.
enum class SynthesisKernel { kBest, kBaseline, kAvx2Fma };
bool SynthesisKernelAvailable(SynthesisKernel kernel);
void RefineAndAddDetails(const LoopHierarchy& hierarchy, int level, const Positions& coarse,
                         const Positions& local, Positions* result,
                         SynthesisKernel kernel = SynthesisKernel::kBest);

// Limit normals only (#V×3 unit rows), same convention as LocalFrames::normal.
Positions LimitNormals(const LoopHierarchy& hierarchy, int level,
                       const Positions& control_points);

}  // namespace subflow::geometry
