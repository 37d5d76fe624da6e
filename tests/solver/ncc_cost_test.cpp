// The residuals of the stereo functional (solver/stereo/ncc_cost.h): the normalization and its
// derivative, the NCC identity ‖r‖² = W (2 − 2 NCC), analytic against numeric Jacobians
// of the patch and silhouette costs, and the signed distance of a disk.
#include <cmath>
#include <random>

#include <Eigen/QR>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "solver/stereo/ncc_cost.h"
#include "vision/camera_rig.h"

namespace subflow::solver {
namespace {

// A smooth pattern (wavelengths ≥ 60 px). The image gradient the costs use is the
// bilinear interpolation of central differences, not the exact derivative of the bilinear
// intensity (which jumps at pixel borders), so on a curved pattern the two agree only to
// O(pixel² · curvature); on a linear ramp (curvature = 0) they agree exactly.
cv::Mat SmoothPattern(int width, int height, bool linear) {
  cv::Mat image(height, width, CV_32FC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      image.at<float>(y, x) =
          linear ? static_cast<float>(0.1 + 0.004 * x + 0.002 * y)
                 : static_cast<float>(0.5 + 0.2 * std::sin(0.1 * x) * std::cos(0.08 * y) +
                                      0.1 * std::sin(0.05 * (x + 2 * y)));
  return image;
}

struct Fixture {
  vision::Camera camera_a = vision::LookAtCamera("a", 200, 160, 300.0, {0.1, 0.0, 1.0}, {0, 0, 0});
  vision::Camera camera_b = vision::LookAtCamera("b", 200, 160, 300.0, {-0.1, 0.05, 1.0}, {0, 0, 0});
  SmoothedImage image_a, image_b;
  PatchStencil stencil;
  std::vector<Eigen::Matrix3d> basis;
  std::vector<int> support = {0, 1, 2};  // the views read basis[support[j]]
  geometry::Positions base;              // X⁰, one row per sample
  std::vector<double> parameters;        // 3 blocks × dof

  explicit Fixture(int dof, bool linear_images = false) {
    image_a = SmoothImage(SmoothPattern(200, 160, linear_images), 1.0);
    // Camera b sees another pattern: a ramp in another direction, or a gain/offset copy.
    image_b = linear_images ? SmoothImage(SmoothPattern(160, 200, true).t(), 1.0)
                            : SmoothImage(SmoothPattern(200, 160, false) * 0.7 + 0.1, 1.0);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const int m = 9, vertices = 3;
    stencil.resize(m, vertices);
    base.resize(m, 3);
    for (int k = 0; k < m; ++k) {
      for (int j = 0; j < vertices; ++j) stencil(k, j) = uniform(random);
      stencil.row(k) /= stencil.row(k).sum();
      base.row(k) << 0.01 * (k % 3) - 0.01, 0.01 * (k / 3) - 0.01, 0.002 * k;
    }
    for (int j = 0; j < vertices; ++j) {
      Eigen::Matrix3d B = Eigen::Matrix3d::Random();
      basis.push_back(Eigen::HouseholderQR<Eigen::Matrix3d>(B).householderQ());
    }
    parameters.resize(static_cast<std::size_t>(vertices) * dof);
    for (double& p : parameters) p = 0.002 * (uniform(random) - 0.5);
  }
  PatchView View(const vision::Camera& camera, const SmoothedImage& image, int first_block) const {
    return PatchView{&image, &camera, {&base, 0, static_cast<int>(base.rows())}, {&basis, &support}, first_block};
  }
};

// Three views of the patch on linear images (a third camera sees image a again) compared
// by three pairs on overlapping rows with different weights: 9 + 5 + 5 = 19 residuals on
// 3 blocks of dof 1. The views point into the fixture, which is therefore not copied.
struct ThreeViewFixture : Fixture {
  vision::Camera camera_c = vision::LookAtCamera("c", 200, 160, 300.0, {0.0, -0.1, 1.0}, {0, 0, 0});
  std::vector<PatchView> views = {View(camera_a, image_a, 0), View(camera_b, image_b, 0), View(camera_c, image_a, 0)};
  std::vector<CorrelationPair> pairs = {{0, 1, {0, 1, 2, 3, 4, 5, 6, 7, 8}, 0.9},
                                        {0, 2, {1, 2, 4, 5, 7}, 0.5},
                                        {1, 2, {0, 3, 6, 7, 8}, 0.25}};

  ThreeViewFixture() : Fixture(1, true) {}
  ThreeViewFixture(const ThreeViewFixture&) = delete;
};

// Central differences of a cost function's residuals w.r.t. every parameter.
void ExpectJacobiansMatch(const ceres::CostFunction& cost, std::vector<double*> blocks,
                          double step, double tolerance) {
  const int residuals = cost.num_residuals();
  const auto& sizes = cost.parameter_block_sizes();
  std::vector<std::vector<double>> analytic(sizes.size());
  std::vector<double*> jacobians(sizes.size());
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    analytic[b].resize(static_cast<std::size_t>(residuals) * sizes[b]);
    jacobians[b] = analytic[b].data();
  }
  std::vector<double> r0(residuals), rp(residuals), rm(residuals);
  ASSERT_TRUE(cost.Evaluate(blocks.data(), r0.data(), jacobians.data()));
  double largest = 0.0;
  for (const auto& J : analytic)
    for (double value : J) largest = std::max(largest, std::abs(value));
  ASSERT_GT(largest, 0.0);
  for (std::size_t b = 0; b < sizes.size(); ++b)
    for (int d = 0; d < sizes[b]; ++d) {
      const double saved = blocks[b][d];
      blocks[b][d] = saved + step;
      cost.Evaluate(blocks.data(), rp.data(), nullptr);
      blocks[b][d] = saved - step;
      cost.Evaluate(blocks.data(), rm.data(), nullptr);
      blocks[b][d] = saved;
      for (int r = 0; r < residuals; ++r) {
        const double numeric = (rp[r] - rm[r]) / (2.0 * step);
        EXPECT_NEAR(analytic[b][static_cast<std::size_t>(r) * sizes[b] + d], numeric, tolerance * largest)
            << "block " << b << " component " << d << " residual " << r;
      }
    }
}

TEST(NormalizeIntensities, ZeroMeanUnitNormAndExactDerivative) {
  const Eigen::VectorXd x = (Eigen::VectorXd(6) << 0.2, 0.5, 0.1, 0.9, 0.4, 0.3).finished();
  const Eigen::VectorXd n = NormalizeIntensities(x, 0.0);
  EXPECT_NEAR(n.mean(), 0.0, 1e-15);
  EXPECT_NEAR(n.norm(), 1.0, 1e-15);
  // Invariant to gain and offset (eq. 5: brightness up to a linear transformation).
  EXPECT_LT((NormalizeIntensities(3.0 * x.array() + 0.7, 0.0) - n).norm(), 1e-14);

  for (double epsilon : {0.0, 0.05}) {
    RowJacobian J = RowJacobian::Identity(6, 6);
    const Eigen::VectorXd base = NormalizeIntensities(x, epsilon, &J);
    for (int i = 0; i < 6; ++i) {
      Eigen::VectorXd xp = x, xm = x;
      xp(i) += 1e-6;
      xm(i) -= 1e-6;
      const Eigen::VectorXd numeric =
          (NormalizeIntensities(xp, epsilon) - NormalizeIntensities(xm, epsilon)) / 2e-6;
      EXPECT_LT((J.col(i) - numeric).norm(), 1e-8) << "epsilon " << epsilon << " column " << i;
    }
    // With the noise floor a textureless vector is damped towards zero instead of blown up.
    if (epsilon > 0) {
      const Eigen::VectorXd flat = NormalizeIntensities(x.array() * 1e-3 + 0.5, epsilon);
      EXPECT_LT(flat.norm(), 0.02);
      EXPECT_LT(base.norm(), 1.0);
    }
  }
}

TEST(PatchCorrelationCost, SquaredResidualIsTwoMinusTwoNcc) {
  const Fixture fixture(3);
  const double weight = 0.6;
  const PatchCorrelationCost cost(fixture.stencil, fixture.View(fixture.camera_a, fixture.image_a, 0),
                                  fixture.View(fixture.camera_b, fixture.image_b, 0), 3, 3, weight, 0.0);
  std::vector<double> params = fixture.parameters;
  const double* blocks[3] = {params.data(), params.data() + 3, params.data() + 6};
  Eigen::VectorXd r(9);
  ASSERT_TRUE(cost.Evaluate(blocks, r.data(), nullptr));
  // The NCC computed directly from the sampled intensities.
  Eigen::VectorXd xa, xb;
  SampleView(fixture.View(fixture.camera_a, fixture.image_a, 0), fixture.stencil, 3, blocks, &xa, nullptr);
  SampleView(fixture.View(fixture.camera_b, fixture.image_b, 0), fixture.stencil, 3, blocks, &xb, nullptr);
  const Eigen::VectorXd ya = xa.array() - xa.mean(), yb = xb.array() - xb.mean();
  const double ncc = ya.dot(yb) / (ya.norm() * yb.norm());
  EXPECT_NEAR(r.squaredNorm(), weight * (2.0 - 2.0 * ncc), 1e-12);
  EXPECT_GT(std::abs(ncc), 0.0);
}

// Exact on linear ramps (the chain rule through stencil, basis, projection and
// normalization), and within the interpolation mismatch on a curved pattern.
TEST(PatchCorrelationCost, AnalyticJacobianMatchesNumeric) {
  for (bool linear : {true, false}) {
    // Step 1e-5 m ≈ 3e-3 px: above the float32 rounding of the images, far below a pixel.
    // Curved: the interpolated gradient is constant across a pixel cell in the other
    // direction only approximately (±k·amplitude), so entries agree to ~10 % of the largest.
    const double tolerance = linear ? 2e-4 : 0.15;  // linear: float32 images
    for (int dof : {1, 3}) {
      Fixture fixture(dof, linear);
      // Stereo form: both views share the frame's blocks.
      const PatchCorrelationCost stereo(fixture.stencil, fixture.View(fixture.camera_a, fixture.image_a, 0),
                                        fixture.View(fixture.camera_b, fixture.image_b, 0), 3, dof, 0.8, 0.01);
      std::vector<double> params = fixture.parameters;
      SCOPED_TRACE(std::string(linear ? "linear" : "curved") + " images, dof " + std::to_string(dof));
      ExpectJacobiansMatch(stereo, {params.data(), params.data() + dof, params.data() + 2 * dof}, 1e-5,
                           tolerance);
      // Temporal form: one camera, two frames, separate blocks.
      std::vector<double> later = fixture.parameters;
      for (double& p : later) p *= -0.5;
      const PatchCorrelationCost temporal(fixture.stencil, fixture.View(fixture.camera_a, fixture.image_a, 0),
                                          fixture.View(fixture.camera_a, fixture.image_b, 3), 6, dof, 1.0, 0.01);
      ExpectJacobiansMatch(temporal,
                           {params.data(), params.data() + dof, params.data() + 2 * dof, later.data(),
                            later.data() + dof, later.data() + 2 * dof},
                           1e-5, tolerance);
    }
  }
}

// Several pairs in one block: each pair normalized on its own rows, residuals concatenated.
TEST(PatchCorrelationCost, MultiplePairsAddUpAndDifferentiate) {
  const ThreeViewFixture fixture;
  const PatchCorrelationCost cost(fixture.stencil, fixture.views, fixture.pairs, 3, 1, 0.0);
  ASSERT_EQ(cost.num_residuals(), 19);
  std::vector<double> params = fixture.parameters;
  const double* blocks[3] = {params.data(), params.data() + 1, params.data() + 2};
  Eigen::VectorXd r(19);
  ASSERT_TRUE(cost.Evaluate(blocks, r.data(), nullptr));
  double expected = 0.0;
  for (const CorrelationPair& pair : fixture.pairs) {
    Eigen::VectorXd xa, xb;
    SampleView(fixture.views[pair.a], fixture.stencil, 1, blocks, &xa, nullptr);
    SampleView(fixture.views[pair.b], fixture.stencil, 1, blocks, &xb, nullptr);
    Eigen::VectorXd ya(pair.rows.size()), yb(pair.rows.size());
    for (std::size_t i = 0; i < pair.rows.size(); ++i) {
      ya(i) = xa(pair.rows[i]);
      yb(i) = xb(pair.rows[i]);
    }
    ya.array() -= ya.mean();
    yb.array() -= yb.mean();
    expected += pair.weight * (2.0 - 2.0 * ya.dot(yb) / (ya.norm() * yb.norm()));
  }
  EXPECT_NEAR(r.squaredNorm(), expected, 1e-12);
  ExpectJacobiansMatch(cost, {params.data(), params.data() + 1, params.data() + 2}, 1e-5, 2e-4);
  // Bad pairs are refused.
  EXPECT_THROW(PatchCorrelationCost(fixture.stencil, fixture.views, {{0, 0, {0, 1}, 1.0}}, 3, 1, 0.0), Error);
  EXPECT_THROW(PatchCorrelationCost(fixture.stencil, fixture.views, {{0, 3, {0, 1}, 1.0}}, 3, 1, 0.0), Error);
  EXPECT_THROW(PatchCorrelationCost(fixture.stencil, fixture.views, {{0, 1, {0, 9}, 1.0}}, 3, 1, 0.0), Error);
  EXPECT_THROW(PatchCorrelationCost(fixture.stencil, fixture.views, {}, 3, 1, 0.0), Error);
}

// The reduced form (UseReducedForm): n + 1 residuals instead of m with the same squared
// norm, normal matrix JᵀJ and gradient Jᵀr as the full block, so Ceres takes the same
// steps; the pairs' own residuals stay readable; blocks with m ≤ n + 1 are left as they are.
TEST(PatchCorrelationCost, ReducedFormKeepsTheNormalEquationsAndTheCost) {
  const ThreeViewFixture fixture;
  const PatchCorrelationCost full(fixture.stencil, fixture.views, fixture.pairs, 3, 1, 0.01);
  PatchCorrelationCost reduced(fixture.stencil, fixture.views, fixture.pairs, 3, 1, 0.01);
  reduced.UseReducedForm();
  ASSERT_TRUE(reduced.reduced());
  ASSERT_EQ(full.num_residuals(), 19);
  ASSERT_EQ(reduced.num_residuals(), 4);
  ASSERT_EQ(reduced.pair_residual_count(), 19);

  std::vector<double> params = fixture.parameters;
  const double* blocks[3] = {params.data(), params.data() + 1, params.data() + 2};
  // Full: r (19) and J (19 × 3); reduced: r̃ (4) and J̃ (4 × 3), one column per block (dof 1).
  Eigen::VectorXd r(19), rr(4);
  Eigen::Matrix<double, 19, 3> J;
  Eigen::Matrix<double, 4, 3> JJ;
  std::vector<double> columns(19 * 3), reduced_columns(4 * 3);
  double* jacobians[3] = {columns.data(), columns.data() + 19, columns.data() + 38};
  double* reduced_jacobians[3] = {reduced_columns.data(), reduced_columns.data() + 4, reduced_columns.data() + 8};
  ASSERT_TRUE(full.Evaluate(blocks, r.data(), jacobians));
  ASSERT_TRUE(reduced.Evaluate(blocks, rr.data(), reduced_jacobians));
  for (int b = 0; b < 3; ++b) {
    J.col(b) = Eigen::Map<Eigen::VectorXd>(jacobians[b], 19);
    JJ.col(b) = Eigen::Map<Eigen::VectorXd>(reduced_jacobians[b], 4);
  }
  ASSERT_GT(J.norm(), 0.0);
  EXPECT_NEAR(rr.squaredNorm(), r.squaredNorm(), 1e-12 * r.squaredNorm());
  const Eigen::Matrix3d normal = J.transpose() * J;
  EXPECT_LT((JJ.transpose() * JJ - normal).norm(), 1e-10 * normal.norm());
  EXPECT_LT((JJ.transpose() * rr - J.transpose() * r).norm(), 1e-10 * (J.transpose() * r).norm());
  EXPECT_EQ(JJ.row(3).norm(), 0.0);
  // The full model cost ½‖Jδ + r‖² equals the reduced one for any step δ, to rounding of
  // the cost itself (‖Jδ‖² is 90 times ‖r‖² here).
  const Eigen::Vector3d step(0.3, -0.2, 0.5);
  const double model_cost = (J * step + r).squaredNorm();
  EXPECT_NEAR((JJ * step + rr).squaredNorm(), model_cost, 1e-10 * model_cost);

  // Residuals only: the same norm; the pairs' residuals are those of the full block.
  Eigen::VectorXd cost_only(4), pair_residuals(19);
  ASSERT_TRUE(reduced.Evaluate(blocks, cost_only.data(), nullptr));
  EXPECT_NEAR(cost_only.squaredNorm(), r.squaredNorm(), 1e-12 * r.squaredNorm());
  reduced.PairResiduals(blocks, pair_residuals.data());
  EXPECT_EQ((pair_residuals - r).norm(), 0.0);

  // One pair of 9 samples on 3 blocks of 3: 9 residuals ≤ 9 + 1, nothing to reduce.
  PatchCorrelationCost small(fixture.stencil, fixture.View(fixture.camera_a, fixture.image_a, 0),
                             fixture.View(fixture.camera_b, fixture.image_b, 0), 3, 3, 1.0, 0.0);
  small.UseReducedForm();
  EXPECT_FALSE(small.reduced());
  EXPECT_EQ(small.num_residuals(), 9);
}

TEST(PatchCorrelationCost, RejectsInconsistentViews) {
  const Fixture fixture(3);
  PatchView short_view = fixture.View(fixture.camera_a, fixture.image_a, 0);
  short_view.base.count -= 1;
  EXPECT_THROW(PatchCorrelationCost(fixture.stencil, short_view,
                                    fixture.View(fixture.camera_b, fixture.image_b, 0), 3, 3, 1.0, 0.0),
               Error);
  EXPECT_THROW(PatchCorrelationCost(fixture.stencil, fixture.View(fixture.camera_a, fixture.image_a, 1),
                                    fixture.View(fixture.camera_b, fixture.image_b, 0), 3, 3, 1.0, 0.0),
               Error);
  EXPECT_THROW(PatchCorrelationCost(fixture.stencil, fixture.View(fixture.camera_a, fixture.image_a, 0),
                                    fixture.View(fixture.camera_b, fixture.image_b, 0), 3, 2, 1.0, 0.0),
               Error);
}

TEST(SignedDistance, DiskOutlineIsWithinHalfAPixel) {
  cv::Mat mask = cv::Mat::zeros(101, 121, CV_8UC1);
  const double cx = 60.0, cy = 50.0, radius = 30.0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (std::hypot(x - cx, y - cy) <= radius) mask.at<std::uint8_t>(y, x) = 255;
  const SignedDistanceImage sdf = ComputeSignedDistance(mask);
  double worst = 0.0;
  for (int y = 5; y < mask.rows - 5; ++y)
    for (int x = 5; x < mask.cols - 5; ++x) {
      const double truth = std::hypot(x - cx, y - cy) - radius;
      if (std::abs(truth) > 10) continue;
      worst = std::max(worst, std::abs(sdf.distance.at<float>(y, x) - truth));
    }
  EXPECT_LT(worst, 0.75);  // pixelized outline: within about half a pixel
  EXPECT_GT(sdf.distance.at<float>(0, 0), 40.0f);
  EXPECT_LT(sdf.distance.at<float>(50, 60), -25.0f);
  EXPECT_THROW(ComputeSignedDistance(cv::Mat()), Error);
  EXPECT_THROW(ComputeSignedDistance(cv::Mat::zeros(4, 4, CV_32FC1)), Error);
}

// The gradient SampleSignedDistance takes from the distance plane at sampling time is, to
// the bit, the bilinear interpolation of cv::Sobel's planes (3×3, / 8, replicated border),
// everywhere a sample is defined: a disk's distance and random values, inside and at the
// four borders, on an image wider than OpenCV's vector width and on a tiny one.
TEST(SignedDistance, GradientAtSamplingTimeIsSobelsPlanesToTheBit) {
  cv::Mat mask = cv::Mat::zeros(101, 121, CV_8UC1);
  cv::circle(mask, {60, 50}, 30, cv::Scalar(255), cv::FILLED);
  cv::Mat noise(5, 7, CV_32FC1);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, -40.0, 40.0);
  for (const SignedDistanceImage& sdf : {ComputeSignedDistance(mask), SignedDistanceImage{noise}}) {
    cv::Mat gx, gy;
    cv::Sobel(sdf.distance, gx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0, cv::BORDER_REPLICATE);
    cv::Sobel(sdf.distance, gy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0, cv::BORDER_REPLICATE);
    const auto bilinear = [](const cv::Mat& plane, double x, double y) {  // as the planes were sampled
      double value = 0.0;
      EXPECT_TRUE(SampleScalar(plane, Eigen::Vector2d(x, y), &value));
      return value;
    };
    int sampled = 0, differing = 0;
    for (double y = 0.0; y <= sdf.distance.rows - 1.0; y += 0.23) {
      for (double x = 0.0; x <= sdf.distance.cols - 1.0; x += 0.29) {
        double value = 0.0;
        Eigen::Vector2d gradient;
        if (!SampleSignedDistance(sdf, Eigen::Vector2d(x, y), &value, &gradient)) continue;
        ++sampled;
        differing += value != bilinear(sdf.distance, x, y) || gradient.x() != bilinear(gx, x, y) ||
                     gradient.y() != bilinear(gy, x, y);
      }
    }
    EXPECT_GT(sampled, 250);
    EXPECT_EQ(differing, 0) << sdf.distance.cols << "×" << sdf.distance.rows;
  }
  double value = 0.0;
  Eigen::Vector2d gradient;
  EXPECT_FALSE(SampleSignedDistance(ComputeSignedDistance(mask), Eigen::Vector2d(120.5, 3.0), &value, &gradient));
}

TEST(SilhouetteCost, PullsOutsidePointsAndMatchesNumericJacobian) {
  const vision::Camera camera = vision::LookAtCamera("c", 200, 160, 300.0, {0.0, 0.0, 1.0}, {0, 0, 0});
  cv::Mat mask = cv::Mat::zeros(160, 200, CV_8UC1);
  cv::circle(mask, {100, 80}, 30, cv::Scalar(255), cv::FILLED);
  const SignedDistanceImage sdf = ComputeSignedDistance(mask);
  // A point projecting ~10 px right of the disk's outline.
  const Eigen::Vector3d outside(0.135, 0.0, 0.0);
  const std::vector<Eigen::Matrix3d> bases(2, Eigen::Matrix3d::Identity());
  const std::vector<int> support = {1, 0};
  const SupportBases basis{&bases, &support};
  const Eigen::VectorXd stencil = Eigen::Vector2d(0.7, 0.3);
  const SilhouetteCost one_sided(&sdf, &camera, outside, stencil, basis, 3, 0.5, true);
  std::vector<double> e(6, 0.0);
  e[0] = 0.001;
  double r = 0.0;
  const double* blocks[2] = {e.data(), e.data() + 3};
  ASSERT_TRUE(one_sided.Evaluate(blocks, &r, nullptr));
  EXPECT_GT(r, 0.5 * 5.0);
  ExpectJacobiansMatch(one_sided, {e.data(), e.data() + 3}, 1e-7, 0.05);
  // Inside, the one-sided term is inactive; the two-sided one is not.
  const Eigen::Vector3d inside(0.02, 0.0, 0.0);
  const SilhouetteCost inactive(&sdf, &camera, inside, stencil, basis, 3, 0.5, true);
  ASSERT_TRUE(inactive.Evaluate(blocks, &r, nullptr));
  EXPECT_EQ(r, 0.0);
  const SilhouetteCost rim(&sdf, &camera, inside, stencil, basis, 3, 0.5, false);
  ASSERT_TRUE(rim.Evaluate(blocks, &r, nullptr));
  EXPECT_LT(r, -0.5 * 10.0);
}

}  // namespace
}  // namespace subflow::solver
