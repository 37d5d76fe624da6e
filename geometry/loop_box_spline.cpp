#include "geometry/loop_box_spline.h"

namespace subflow::geometry {
namespace {

// Monomials w0^a w1^b w2^c (a + b + c = 4) in the homogeneous barycentrics
// (w0, w1, w2) = (1 − u − v, u, v), Stam's (u, v, w).
struct Monomial {
  int a, b, c;
};
constexpr std::array<Monomial, 15> kMonomials = {{{4, 0, 0}, {3, 1, 0}, {3, 0, 1}, {2, 2, 0},
                                                  {2, 1, 1}, {2, 0, 2}, {1, 3, 0}, {1, 2, 1},
                                                  {1, 1, 2}, {1, 0, 3}, {0, 4, 0}, {0, 3, 1},
                                                  {0, 2, 2}, {0, 1, 3}, {0, 0, 4}}};

// 12 × the coefficient of each monomial in each basis function (Stam 1998, appendix).
// Columns follow kMonomials: w0^4, w0^3w1, w0^3w2, w0^2w1^2, w0^2w1w2, w0^2w2^2, w0w1^3,
// w0w1^2w2, w0w1w2^2, w0w2^3, w1^4, w1^3w2, w1^2w2^2, w1w2^3, w2^4.
constexpr int kCoefficients[12][15] = {
    {1, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {1, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {1, 6, 2, 12, 6, 0, 6, 6, 0, 0, 1, 2, 0, 0, 0},
    {6, 24, 24, 24, 60, 24, 8, 36, 36, 8, 1, 6, 12, 6, 1},
    {1, 2, 6, 0, 6, 12, 0, 0, 6, 6, 0, 0, 0, 2, 1},
    {0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 0},
    {1, 8, 6, 24, 36, 12, 24, 60, 36, 6, 6, 24, 24, 8, 1},
    {1, 6, 8, 12, 36, 24, 6, 36, 60, 24, 1, 8, 24, 24, 6},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2, 0, 0, 0},
    {0, 0, 0, 0, 0, 0, 2, 6, 6, 2, 1, 6, 12, 6, 1},
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 1},
};

}  // namespace

const std::array<BoxSplineControlSlot, 12> kBoxSplineControlSlots = {{
    {0, 4}, {0, 3}, {0, 5}, {0, -1}, {0, 2}, {1, 3},
    {1, -1}, {2, -1}, {2, 4}, {1, 4}, {1, 5}, {2, 3},
}};

void LoopBoxSplineBasis(double u, double v, std::array<double, 12>* value,
                        std::array<double, 12>* d_du, std::array<double, 12>* d_dv) {
  const double w[3] = {1.0 - u - v, u, v};
  double power[3][5];
  for (int k = 0; k < 3; ++k) {
    power[k][0] = 1.0;
    for (int e = 1; e <= 4; ++e) power[k][e] = power[k][e - 1] * w[k];
  }
  // Each monomial and its partial derivatives in the homogeneous barycentrics; with
  // w0 = 1 − u − v, ∂/∂u = ∂/∂w1 − ∂/∂w0 and ∂/∂v = ∂/∂w2 − ∂/∂w0.
  double m[15], m_du[15], m_dv[15];
  for (int i = 0; i < 15; ++i) {
    const auto [a, b, c] = kMonomials[i];
    m[i] = power[0][a] * power[1][b] * power[2][c];
    const double d0 = a > 0 ? a * power[0][a - 1] * power[1][b] * power[2][c] : 0.0;
    const double d1 = b > 0 ? b * power[0][a] * power[1][b - 1] * power[2][c] : 0.0;
    const double d2 = c > 0 ? c * power[0][a] * power[1][b] * power[2][c - 1] : 0.0;
    m_du[i] = d1 - d0;
    m_dv[i] = d2 - d0;
  }
  for (int j = 0; j < 12; ++j) {
    double s = 0.0, s_du = 0.0, s_dv = 0.0;
    for (int i = 0; i < 15; ++i) {
      const int k = kCoefficients[j][i];
      if (k == 0) continue;
      s += k * m[i];
      s_du += k * m_du[i];
      s_dv += k * m_dv[i];
    }
    (*value)[j] = s / 12.0;
    if (d_du) (*d_du)[j] = s_du / 12.0;
    if (d_dv) (*d_dv)[j] = s_dv / 12.0;
  }
}

}  // namespace subflow::geometry
