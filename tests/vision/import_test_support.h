// Helpers of the importer tests (tests/vision/import_*_test.cpp): rigs of known cameras
// looking at a working volume, points in it, and OpenCV's projection formula written out
// by hand (the formula every source tool documents), independent of vision::Camera.
#pragma once

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/error.h"

namespace subflow::test {

// A camera as the tests define it: OpenCV convention, Xc = R X + t.
struct TruthCamera {
  std::string name;
  int width = 0, height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity(), R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::VectorXd distortion = Eigen::VectorXd::Zero(5);  // k1 k2 p1 p2 k3
  Eigen::Vector3d Centre() const { return -R.transpose() * t; }
};

// R of a camera at `centre` looking at `target`, with world `up` pointing up in its image
// (OpenCV: +z forward, +y down).
inline Eigen::Matrix3d LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target,
                              const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = z.cross(up).normalized();  // right = forward × up... then y = z × x is down
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  return R;
}

// `count` cameras on a ring of `radius` at `height` (along `up`) looking at the origin,
// width × height pixels, focal `focal` px, principal point off centre, some distortion.
inline std::vector<TruthCamera> RingRig(int count, double radius, double height, const Eigen::Vector3d& up,
                                        int width, int image_height, double focal) {
  std::vector<TruthCamera> rig;
  const Eigen::Vector3d a = up.unitOrthogonal(), b = up.cross(a);
  for (int i = 0; i < count; ++i) {
    const double angle = 2 * M_PI * i / count + 0.3;
    TruthCamera camera;
    char name[16];
    std::snprintf(name, sizeof(name), "cam%02d", i + 1);
    camera.name = name;
    camera.width = width;
    camera.height = image_height;
    camera.K << focal * (1 + 0.01 * i), 0, 0.5 * width - 3.5 + i, 0, focal * (1 + 0.008 * i), 0.5 * image_height + 2.25 - i,
        0, 0, 1;
    const Eigen::Vector3d centre = radius * (std::cos(angle) * a + std::sin(angle) * b) + height * up;
    camera.R = LookAt(centre, 0.3 * height * up, up);
    camera.t = -camera.R * centre;
    camera.distortion << -0.04 - 0.01 * i, 0.012, 0.0007 * (i - 1), -0.0004 * i, 0.0;
    rig.push_back(camera);
  }
  return rig;
}

// Points spread in the cube of half-size `half` around `centre`.
inline std::vector<Eigen::Vector3d> PointsAround(const Eigen::Vector3d& centre, double half, int count) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(-half, half);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) points.push_back(centre + Eigen::Vector3d(u(random), u(random), u(random)));
  return points;
}

// OpenCV's (and Pose2Sim's, Anipose's, EasyMocap's, Panoptic's) projection, written out:
// x = Xc.x / Xc.z, y = Xc.y / Xc.z, r² = x² + y²,
// x' = x (1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2x²), y' likewise, u = fx x' + cx.
inline Eigen::Vector2d OpenCvProject(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                     const Eigen::VectorXd& d, const Eigen::Vector3d& X) {
  const Eigen::Vector3d Xc = R * X + t;
  const double x = Xc.x() / Xc.z(), y = Xc.y() / Xc.z(), r2 = x * x + y * y;
  const double k1 = d.size() > 0 ? d[0] : 0, k2 = d.size() > 1 ? d[1] : 0, p1 = d.size() > 2 ? d[2] : 0,
               p2 = d.size() > 3 ? d[3] : 0, k3 = d.size() > 4 ? d[4] : 0;
  const double radial = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {K(0, 0) * xd + K(0, 1) * yd + K(0, 2), K(1, 1) * yd + K(1, 2)};
}

// "%.*g" of `value` (how tools print numbers), for writing test files.
inline std::string Printed(double value, int digits = 17) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*g", digits, value);
  return text;
}

template <typename Action>
std::string ErrorOf(Action action) {
  try {
    action();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace subflow::test
