// Claims about vision::Camera: it projects like OpenCV (its five-coefficient, rational and
// fisheye distortion models included), its Jacobian is the derivative of its projection,
// back-projection inverts projection, near-rotations are re-orthonormalized and clear
// non-rotations refused, and the pixel-centre convention of ../shared/DATASET.md holds.
#include "vision/camera.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "core/error.h"
#include "vision/rotation.h"

namespace subflow::vision {
namespace {

Eigen::Matrix3d TestK() {
  Eigen::Matrix3d K;
  K << 410.0, 0.0, 161.3, 0.0, 405.0, 118.7, 0.0, 0.0, 1.0;
  return K;
}

Eigen::Matrix3d TestR() {
  return Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, -1.0, 0.2).normalized()).toRotationMatrix();
}

Eigen::VectorXd TestDistortion() {
  Eigen::VectorXd d(5);
  d << -0.21, 0.06, 0.0012, -0.0007, -0.008;
  return d;
}

Camera DistortedCamera() {
  return Camera("cam", 320, 240, TestK(), TestR(), Eigen::Vector3d(0.05, -0.02, 1.2), TestDistortion());
}

// OpenCV's rational model (k4 k5 k6 != 0), as COLMAP's FULL_OPENCV and calibrateCamera's
// CALIB_RATIONAL_MODEL give it.
Camera RationalCamera() {
  Eigen::VectorXd d(8);
  d << 0.35, -0.12, 0.0011, -0.0006, 0.02, 0.55, -0.05, 0.01;
  return Camera("rational", 320, 240, TestK(), TestR(), Eigen::Vector3d(0.05, -0.02, 1.2), d);
}

// cv::fisheye's model (Anipose's FisheyeCamera, COLMAP's OPENCV_FISHEYE).
Camera FisheyeCamera() {
  Eigen::VectorXd d(4);
  d << -0.03, 0.012, -0.004, 0.0007;
  return Camera("fisheye", 320, 240, TestK(), TestR(), Eigen::Vector3d(0.05, -0.02, 1.2), d, "",
                DistortionModel::kFisheye);
}

std::vector<Camera> DistortedCameras() { return {DistortedCamera(), RationalCamera(), FisheyeCamera()}; }

// Random world points in front of `camera`, projecting roughly into its image.
std::vector<Eigen::Vector3d> PointsInView(const Camera& camera, int count) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-0.5, 0.5), depth(0.6, 2.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double z = depth(random);
    const Eigen::Vector3d Xc(u(random) * 0.7 * z, u(random) * 0.5 * z, z);
    points.push_back(camera.R().transpose() * (Xc - camera.t()));
  }
  return points;
}

TEST(Camera, ProjectEqualsOpenCvProjectPoints) {
  for (const Camera& camera : DistortedCameras()) {
    const std::vector<Eigen::Vector3d> points = PointsInView(camera, 200);
    std::vector<cv::Point3d> object;
    for (const auto& X : points) object.emplace_back(X.x(), X.y(), X.z());
    cv::Mat R(3, 3, CV_64F), K(3, 3, CV_64F), rvec, tvec(3, 1, CV_64F);
    for (int r = 0; r < 3; ++r) {
      tvec.at<double>(r) = camera.t()[r];
      for (int c = 0; c < 3; ++c) {
        R.at<double>(r, c) = camera.R()(r, c);
        K.at<double>(r, c) = camera.K()(r, c);
      }
    }
    cv::Mat d(1, static_cast<int>(camera.distortion().size()), CV_64F);
    for (int i = 0; i < d.cols; ++i) d.at<double>(i) = camera.distortion()[i];
    cv::Rodrigues(R, rvec);
    std::vector<cv::Point2d> expected;
    if (camera.distortion_model() == DistortionModel::kFisheye)
      cv::fisheye::projectPoints(object, expected, rvec, tvec, K, d);
    else
      cv::projectPoints(object, rvec, tvec, K, d, expected);
    double worst = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d p = camera.Project(points[i]);
      worst = std::max(worst, (p - Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
    }
    // Same formula in double precision; the Rodrigues round trip costs ~1e-13 relative.
    EXPECT_LT(worst, 1e-8) << camera.name() << ": pixels";
    std::printf("    %s: max |Project - OpenCV| = %.3g px (%d coefficients)\n", camera.name().c_str(), worst,
                d.cols);
  }
}

TEST(Camera, DistortionJacobianMatchesCentralDifferences) {
  for (const Camera& camera : DistortedCameras()) {
    const LensDistortion& lens = camera.lens_distortion();
    const double h = 1e-6;
    double worst = 0;
    for (double x = -0.45; x <= 0.45; x += 0.09)
      for (double y = -0.35; y <= 0.35; y += 0.07) {
        Eigen::Matrix2d J, numeric;
        lens.Distort({x, y}, &J);
        for (int k = 0; k < 2; ++k) {
          const Eigen::Vector2d e = Eigen::Vector2d::Unit(k) * h;
          numeric.col(k) = (lens.Distort(Eigen::Vector2d(x, y) + e) - lens.Distort(Eigen::Vector2d(x, y) - e)) / (2 * h);
        }
        worst = std::max(worst, (J - numeric).norm());
      }
    // Truncation ~ h² × the third derivative (~1e-11) and rounding ~ 1e-16 / h (~1e-10).
    EXPECT_LT(worst, 1e-8) << camera.name();
  }
}

TEST(Camera, ProjectUndistortedIsTheProjectionMatrix) {
  const Camera camera = DistortedCamera();
  for (const auto& X : PointsInView(camera, 50)) {
    const Eigen::Vector3d h = camera.ProjectionMatrix() * X.homogeneous();
    double depth = 0;
    const Eigen::Vector2d p = camera.ProjectUndistorted(X, &depth);
    EXPECT_LT((p - h.hnormalized()).norm(), 1e-9);
    EXPECT_NEAR(depth, h.z(), 1e-12);  // K's last row is (0, 0, 1), so P X's z is the depth
  }
}

TEST(Camera, JacobianMatchesCentralDifferences) {
  Eigen::Matrix3d K = TestK();
  K(0, 1) = 2.5;  // skew, so that every entry of the formula is exercised
  const Camera camera("cam", 320, 240, K, TestR(), Eigen::Vector3d(0.05, -0.02, 1.2));
  const double h = 1e-5;  // metres
  double worst = 0;
  for (const auto& X : PointsInView(camera, 30)) {
    const Eigen::Matrix<double, 2, 3> J = camera.ProjectionJacobian(X);
    Eigen::Matrix<double, 2, 3> numeric;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(k) * h;
      numeric.col(k) = (camera.ProjectUndistorted(X + e) - camera.ProjectUndistorted(X - e)) / (2 * h);
    }
    worst = std::max(worst, (J - numeric).norm() / J.norm());
  }
  // Truncation ~ (h / depth)² ≈ 1e-10 and rounding ~ 1e-16 · |p| / (h · |J|) ≈ 1e-11, relative.
  EXPECT_LT(worst, 1e-7);
  std::printf("    max relative |J − central differences| = %.3g\n", worst);
}

TEST(Camera, BackProjectInvertsProjectWithDistortion) {
  for (const Camera& camera : DistortedCameras()) {
    double worst = 0, worst_undistorted = 0;
    for (double y = 0; y < camera.height(); y += 7.3)
      for (double x = 0; x < camera.width(); x += 7.9) {
        const Eigen::Vector2d pixel(x, y);
        const Eigen::Vector3d ray = camera.BackProject(pixel);
        EXPECT_NEAR(ray.norm(), 1.0, 1e-12);
        worst = std::max(worst, (camera.Project(camera.Center() + 0.8 * ray) - pixel).norm());
        const Eigen::Vector3d pinhole_ray = camera.BackProjectUndistorted(pixel);
        worst_undistorted = std::max(
            worst_undistorted, (camera.ProjectUndistorted(camera.Center() + 1.7 * pinhole_ray) - pixel).norm());
      }
    EXPECT_LT(worst, 1e-6) << camera.name() << ": pixels (the brief's tolerance; Newton polishing reaches ~1e-10)";
    EXPECT_LT(worst_undistorted, 1e-9) << "pixels";
    std::printf("    %s: max |Project(BackProject(p)) - p| = %.3g px (pinhole: %.3g px)\n", camera.name().c_str(),
                worst, worst_undistorted);
  }
}

TEST(Camera, PixelCentreConventionOfInImage) {
  const Camera camera("cam", 320, 240, TestK(), Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1));
  // Pixel (0, 0) is the centre of the top-left pixel: the image is [−½, w−½) × [−½, h−½).
  EXPECT_TRUE(camera.InImage({-0.5, -0.5}));
  EXPECT_FALSE(camera.InImage({-0.5001, 0}));
  EXPECT_FALSE(camera.InImage({0, -0.5001}));
  EXPECT_TRUE(camera.InImage({319.4999, 239.4999}));
  EXPECT_FALSE(camera.InImage({319.5, 100}));
  EXPECT_FALSE(camera.InImage({100, 239.5}));
  EXPECT_FALSE(camera.InImage({0, 0}, 1.0));
  EXPECT_TRUE(camera.InImage({0.5, 0.5}, 1.0));
  // The principal point is where the optical axis lands.
  const Eigen::Vector2d axis = camera.Project(camera.Center() + camera.ViewDirection());
  EXPECT_LT((axis - Eigen::Vector2d(161.3, 118.7)).norm(), 1e-12);
}

TEST(Camera, UndistortImageResamplesToThePinholeCamera) {
 for (const Camera& camera : DistortedCameras()) {
  // A smooth pattern g defined on the undistorted image; the raw image is g at the
  // undistorted position of each raw pixel. Undistorting must give back g.
  auto g = [](const Eigen::Vector2d& q) {
    return 0.5 + 0.25 * std::sin(2 * M_PI * q.x() / 40) * std::cos(2 * M_PI * q.y() / 50);
  };
  cv::Mat raw(camera.height(), camera.width(), CV_32F);
  for (int y = 0; y < raw.rows; ++y)
    for (int x = 0; x < raw.cols; ++x) {
      const Eigen::Vector3d ray = camera.BackProject(Eigen::Vector2d(x, y));
      raw.at<float>(y, x) = static_cast<float>(g(camera.ProjectUndistorted(camera.Center() + ray)));
    }
  const cv::Mat undistorted = camera.UndistortImage(raw);
  ASSERT_EQ(undistorted.size(), raw.size());
  double worst = 0;
  int compared = 0;
  for (int y = 0; y < raw.rows; ++y)
    for (int x = 0; x < raw.cols; ++x) {
      // Only where the raw image covers the undistorted pixel (with a 2-pixel margin).
      const Eigen::Vector2d source = camera.Project(camera.Center() + camera.BackProjectUndistorted({x, y}));
      if (!camera.InImage(source, 2.0)) continue;
      worst = std::max(worst, std::abs(undistorted.at<float>(y, x) - g({x, y})));
      ++compared;
    }
  EXPECT_GT(compared, raw.rows * raw.cols / 2);
  // Bilinear interpolation of g (|g''| ≤ 0.25 (2π/40)² ≈ 0.006 per px²) errs by ≤ ~0.002,
  // plus OpenCV's fixed-point (1/32 px) remap weights: ≤ 0.04 · |∇g| ≈ 0.0016.
  EXPECT_LT(worst, 0.005);
  std::printf("    %s: max undistortion error %.4g over %d pixels\n", camera.name().c_str(), worst, compared);
 }
  const cv::Mat raw = cv::Mat::ones(240, 320, CV_32F);
  const Camera pinhole("pinhole", 320, 240, TestK(), TestR(), Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(cv::norm(pinhole.UndistortImage(raw), raw, cv::NORM_INF), 0.0);
}

// Calibration files print R with 6-8 significant digits (RᵀR - I ~ 1e-6): such an R is
// accepted and replaced by the nearest rotation.
TEST(Camera, AcceptsRoundedRotationsAsTheNearestRotation) {
  for (const int digits : {6, 8}) {
    Eigen::Matrix3d printed = TestR();
    for (int i = 0; i < 9; ++i) {
      char text[32];
      std::snprintf(text, sizeof(text), "%.*g", digits, printed(i / 3, i % 3));
      printed(i / 3, i % 3) = std::atof(text);
    }
    ASSERT_GT((printed.transpose() * printed - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
    const Camera camera("c", 320, 240, TestK(), printed, Eigen::Vector3d(0, 0, 1));
    // Orthonormal to a few units of 2⁻⁵² (the SVD's rounding).
    EXPECT_LT((camera.R().transpose() * camera.R() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_NEAR(camera.R().determinant(), 1.0, 1e-14);
    // The nearest rotation is within the rounding of the printed one: <= ½ · 10^(1-digits).
    EXPECT_LT((camera.R() - TestR()).cwiseAbs().maxCoeff(), std::pow(10.0, 1 - digits)) << digits;
    EXPECT_LT(camera.rotation_correction(), kRotationWarningTolerance) << digits;
  }
  // A larger error (1e-3, beyond printing) is still accepted, with its size reported (and
  // a warning logged).
  Eigen::Matrix3d off = TestR();
  off(0, 0) += 1e-3;
  const Camera camera("c", 320, 240, TestK(), off, Eigen::Vector3d(0, 0, 1));
  EXPECT_GT(camera.rotation_correction(), 1e-4);
  EXPECT_LT(camera.rotation_correction(), 1e-3);
}

TEST(Camera, RejectsScaledAndMirroredMatricesNamingSourceCameraAndField) {
  auto message = [](const Eigen::Matrix3d& R) -> std::string {
    try {
      Camera("cam07", 320, 240, TestK(), R, Eigen::Vector3d::Zero(), Eigen::VectorXd(), "rig.json");
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string scaled = message(1.05 * TestR());
  for (const char* part : {"rig.json", "cam07", "R", "rotation", "scaled"})
    EXPECT_NE(scaled.find(part), std::string::npos) << scaled;
  // A reflection (det = -1) is orthogonal but not a rotation.
  EXPECT_NE(message(-TestR()).find("mirrored"), std::string::npos) << message(-TestR());
  Eigen::Matrix3d sheared = TestR();
  sheared.col(0) += 0.05 * sheared.col(1);
  EXPECT_NE(message(sheared).find("sheared"), std::string::npos) << message(sheared);
}

TEST(Camera, RejectsBadIntrinsicsSizesAndDistortion) {
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d t(0, 0, 1);
  auto message = [&](auto make) -> std::string {
    try {
      make();
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(message([&] { Camera("c", -320, 240, TestK(), R, t); }).find("width"), std::string::npos);
  EXPECT_NE(message([&] { Camera("c", 320, 0, TestK(), R, t); }).find("height"), std::string::npos);
  Eigen::Matrix3d K = TestK();
  K(0, 0) = -K(0, 0);
  EXPECT_NE(message([&] { Camera("c", 320, 240, K, R, t); }).find("fx"), std::string::npos);
  K = TestK();
  K(2, 2) = 2;
  EXPECT_NE(message([&] { Camera("c", 320, 240, K, R, t); }).find("last row"), std::string::npos);
  EXPECT_NE(message([&] { Camera("c", 320, 240, TestK(), R, t, Eigen::VectorXd::Zero(3)); }).find("distortion"),
            std::string::npos);
  EXPECT_NE(message([&] {
              Camera("c", 320, 240, TestK(), R, t, TestDistortion(), "", DistortionModel::kFisheye);
            }).find("fisheye"),
            std::string::npos);
  // Eight values with k4 = k5 = k6 = 0 are the five-value model; otherwise all eight stay.
  Eigen::VectorXd rational = Eigen::VectorXd::Zero(8);
  rational[0] = -0.1;
  EXPECT_EQ(Camera("c", 320, 240, TestK(), R, t, rational).distortion().size(), 5);
  EXPECT_EQ(Camera("c", 320, 240, TestK(), R, t, rational).distortion()[0], -0.1);
  rational[5] = 0.1;
  EXPECT_EQ(Camera("c", 320, 240, TestK(), R, t, rational).distortion(), rational);
}

}  // namespace
}  // namespace subflow::vision
