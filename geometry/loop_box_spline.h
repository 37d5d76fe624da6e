// The regular patch of Loop's scheme: over a triangle whose three corners are interior
// vertices of valence 6, the limit surface is the quartic three-direction box spline,
// i.e. 12 quartic polynomials in the patch's barycentric parameters weighting the 12
// control points of the union of the corners' 1-rings (Stam 1998, "Evaluation of Loop
// subdivision surfaces", appendix; the same polynomials follow from the box spline
// M_{222}). They sum to 1 (affine invariance) and at a corner reduce to Loop's limit mask
// 1/2 (corner) + 1/12 (each of its 6 neighbours).
//
// Parameters: point = (1 − u − v)·C0 + u·C1 + v·C2 for the patch triangle (C0, C1, C2)
// listed counter-clockwise; u, v ≥ 0, u + v ≤ 1 (Stam's (v, w); his u is 1 − u − v).
//
// Control point order (index i here is Stam's vertex i + 1). With R0 the 1-ring of C0
// read counter-clockwise starting at C1 (R0[0] = C1, R0[1] = C2), R1 the 1-ring of C1
// starting at C2 and R2 the 1-ring of C2 starting at C0:
//   0: R0[4]   1: R0[3]   2: R0[5]   3: C0      4: R0[2]   5: R1[3]
//   6: C1      7: C2      8: R2[4]   9: R1[4]  10: R1[5]  11: R2[3]
// (R0[5] = R1[2] lies across edge C0C1, R1[5] = R2[2] across C1C2, R2[5] = R0[2] across C2C0.)
#pragma once

#include <array>

namespace subflow::geometry {

constexpr int kBoxSplineControlCount = 12;

// Values and first derivatives (∂/∂u, ∂/∂v with the convention above) of the 12 basis
// functions at (u, v). Exact polynomials; valid for any (u, v) (no range check).
void LoopBoxSplineBasis(double u, double v, std::array<double, 12>* value,
                        std::array<double, 12>* d_du, std::array<double, 12>* d_dv);

// Where each of the 12 control points sits among the three rings: (ring r, position p)
// means R_r[p] as defined above, or the corner itself when p < 0 (corner r).
struct BoxSplineControlSlot {
  int ring;
  int position;
};
extern const std::array<BoxSplineControlSlot, 12> kBoxSplineControlSlots;

}  // namespace subflow::geometry
