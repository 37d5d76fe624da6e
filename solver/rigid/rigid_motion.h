// The rigid and non-rigid parts of a motion field (method §5): the instantaneous rigid
// motion of the base control trajectories, ∂c⁰/∂t = v + ω × c⁰, fitted by least squares;
// the non-rigid flow = flow − (v + ω × x); the motion energy = flow magnitude summed over
// the sequence, per vertex.
//
// Units and conventions
//   Flows are displacements per frame step (world units per frame, e.g. metres/frame):
//   flow_f(i) = x_i(f + 1) − x_i(f). v is in world units per frame, ω in radians per
//   frame (right-handed, about the world origin: the velocity of point x is v + ω × x).
//
// Finite steps (Cayley). A finite rotation R with Cayley vector w (R = (I − [w]×/2)⁻¹
// (I + [w]×/2), rotation angle θ = 2 atan(|w|/2) about w/|w|) moves x to x' with
//   x' − x = [w]× (x + x')/2   exactly.
// So fitting dc = v + ω × p with p = the MIDPOINTS (x + x')/2 of a rigidly moving point set
// recovers ω = w and the rotation exactly, whatever its size; with p = x (the start
// positions) the fit is the first-order (instantaneous) one, off by O(θ²). RotationAngle()
// converts ω to the angle of its Cayley rotation.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"

namespace subflow::solver {

struct RigidMotion {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();      // translation velocity at the origin
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();  // angular velocity (Cayley vector)
  // Root mean square of |dc − (v + ω × p)| over the fitted points (world units / frame).
  double rms_residual = 0.0;

  // v + ω × x for every row of x (#V×3).
  geometry::Positions Velocity(const geometry::Positions& x) const;
  // Angle of the finite rotation whose Cayley vector is ω: 2 atan(|ω|/2) radians
  // (≈ |ω| for small rotations).
  double RotationAngle() const;
};

// Least squares for (v, ω) in dc(i) = v + ω × p(i) over the rows of p and dc (#P×3 each,
// same row count). Solved about the centroid of p (well conditioned whatever the origin):
// ω from the 3×3 system Σ [q]×ᵀ[q]× ω = Σ [q]×ᵀ (dc − mean dc) with q = p − centroid,
// then v = mean dc − ω × centroid. Throws subflow::Error when the row counts differ, there
// are fewer than 3 points, or the points are (numerically) collinear, which leaves the
// rotation about their line undetermined.
RigidMotion FitRigidMotion(const geometry::Positions& p, const geometry::Positions& dc);

// flow − (v + ω × x), row by row (#V×3). x and flow have the same shape.
geometry::Positions NonRigidFlow(const geometry::Positions& x, const geometry::Positions& flow,
                                 const RigidMotion& rigid);

// Per-vertex flow magnitudes |flow(i)| (#V).
Eigen::VectorXd FlowMagnitudes(const geometry::Positions& flow);

// The flow analysis of a sequence of vertex positions with fixed connectivity (the
// finest control points, or any tessellation evaluated at every frame), for writing as
// vertex properties. Frame f's flow is x(f + 1) − x(f), zero at the last frame.
struct FlowAnalysis {
  std::vector<geometry::Positions> flow;            // per frame, #V×3
  std::vector<geometry::Positions> rigid_flow;      // per frame, v_f + ω_f × x(f)
  std::vector<geometry::Positions> non_rigid_flow;  // per frame, flow − rigid flow
  Eigen::VectorXd motion_energy;                    // #V: Σ_f |flow_f(i)|
  Eigen::VectorXd non_rigid_energy;                 // #V: Σ_f |non_rigid_flow_f(i)|
};

// `positions` holds every frame (#frames ≥ 1, each #V×3, same #V); `rigid` one motion per
// frame step (positions.size() − 1 entries, or positions.size() with the last ignored),
// as fitted on the base control points. The rigid flow of step f is evaluated at the
// midpoints (x(f) + x(f + 1))/2, consistent with the Cayley convention above, so an
// exactly rigid sequence has zero non-rigid flow. Throws subflow::Error on size mismatch.
FlowAnalysis AnalyzeFlow(const std::vector<geometry::Positions>& positions,
                         const std::vector<RigidMotion>& rigid);

// Rigid motion of every frame step from the base control points of each frame
// (c0[f], #V(0)×3): FitRigidMotion(midpoints, c0[f + 1] − c0[f]); frame_count − 1 entries.
std::vector<RigidMotion> FitRigidMotions(const std::vector<geometry::Positions>& c0);

}  // namespace subflow::solver
