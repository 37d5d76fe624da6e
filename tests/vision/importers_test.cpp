// Claims about the importers: a COLMAP text model and 3×4 projection-matrix files give
// back the cameras they were written from, with COLMAP's half-pixel offset removed, and
// malformed files are errors naming the file and line.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "vision/import_colmap.h"
#include "vision/import_projection_matrices.h"
#include "tests/test_support.h"
#include "tests/vision/import_test_support.h"

namespace subflow::vision {
namespace {
namespace fs = std::filesystem;

// This run's scratch directory (removed at exit); each test works below it.
const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("importers_test");
  return scratch;
}

using test::ErrorOf;

#define EXPECT_CONTAINS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

std::string Number(double value) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

Eigen::Matrix3d RandomRotation(std::mt19937& random) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(random), n(random), n(random), n(random)).normalized().toRotationMatrix();
}

TEST(ColmapImport, RecoversCamerasAndRemovesTheHalfPixelOffset) {
  const fs::path dir = Scratch().Subdirectory("colmap");
  std::mt19937 random(3);
  // COLMAP cameras: id → (model, width, height, params). Principal points in COLMAP's
  // convention (centre of the top-left pixel at (0.5, 0.5)).
  std::ofstream cameras(dir / "cameras.txt");
  cameras << "# Camera list with one line of data per camera:\n"
             "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
             "1 PINHOLE 640 480 500.25 501.5 320 240\n"
             "2 SIMPLE_PINHOLE 320 240 410 160 120\n"
             "3 OPENCV 800 600 700 702 400.5 299.5 -0.12 0.03 0.001 -0.002\n"
             "4 SIMPLE_RADIAL 320 240 400 161 119 -0.05\n";
  cameras.close();
  struct Pose {
    std::string name;
    int camera_id;
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
  };
  std::vector<Pose> poses;
  std::ofstream images(dir / "images.txt");
  images << "# Image list with two lines of data per image:\n"
            "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
            "#   POINTS2D[] as (X, Y, POINT3D_ID)\n";
  const char* names[] = {"cam02/000000.png", "cam00/000000.png", "cam01/000000.png", "cam03/000000.png"};
  for (int i = 0; i < 4; ++i) {
    Pose pose{fs::path(names[i]).parent_path().string(), 1 + (i + 1) % 4, RandomRotation(random),
              Eigen::Vector3d(0.1 * i, -0.2, 2.0 + i)};
    const Eigen::Quaterniond q(pose.R);
    images << i + 1 << " " << Number(q.w()) << " " << Number(q.x()) << " " << Number(q.y()) << " "
           << Number(q.z()) << " " << Number(pose.t.x()) << " " << Number(pose.t.y()) << " "
           << Number(pose.t.z()) << " " << pose.camera_id << " " << names[i] << "\n";
    // The POINTS2D line: empty for some images (COLMAP writes an empty line then).
    images << (i % 2 ? "" : "12.5 13.5 -1 100.25 40.75 7") << "\n";
    poses.push_back(pose);
  }
  images.close();

  ColmapImportOptions options;
  options.name_from = ColmapImportOptions::NameFrom::kParentFolder;
  const std::vector<Camera> read = ReadColmapTextModel(dir.string(), options);
  ASSERT_EQ(read.size(), 4u);
  const double colmap_c[5][2] = {{0, 0}, {320, 240}, {160, 120}, {400.5, 299.5}, {161, 119}};
  for (const Pose& pose : poses) {
    const auto it = std::find_if(read.begin(), read.end(), [&](const Camera& c) { return c.name() == pose.name; });
    ASSERT_NE(it, read.end()) << pose.name;
    // Quaternion printed with 17 digits: R and t come back to rounding.
    EXPECT_LT((it->R() - pose.R).cwiseAbs().maxCoeff(), 1e-14) << pose.name;
    EXPECT_EQ(it->t(), pose.t);
    EXPECT_EQ(it->K()(0, 2), colmap_c[pose.camera_id][0] - 0.5) << "cx_ours = cx_colmap − 0.5";
    EXPECT_EQ(it->K()(1, 2), colmap_c[pose.camera_id][1] - 0.5) << "cy_ours = cy_colmap − 0.5";
  }
  EXPECT_EQ(read[0].name(), "cam00");  // sorted by name
  const Camera& opencv_camera = read[0];  // cam00 → image 2 → camera id 3 (OPENCV)
  EXPECT_EQ(opencv_camera.width(), 800);
  EXPECT_EQ(opencv_camera.K()(0, 0), 700);
  EXPECT_EQ(opencv_camera.K()(1, 1), 702);
  EXPECT_EQ(opencv_camera.distortion()[0], -0.12);
  EXPECT_EQ(opencv_camera.distortion()[3], -0.002);
  EXPECT_EQ(read[1].distortion()[0], -0.05);  // cam01 → image 3 → camera id 4 (SIMPLE_RADIAL)

  // The same 3D point: COLMAP's pixel (its projection with its cx, cy) is ours + (0.5, 0.5).
  const Camera& pinhole = read[2];  // cam02 → image 1 → camera id 2 (SIMPLE_PINHOLE)
  const Eigen::Vector3d X(0.05, -0.03, 0.02);
  const Eigen::Vector3d Xc = pinhole.ToCamera(X);
  const Eigen::Vector2d colmap_pixel(410 * Xc.x() / Xc.z() + 160, 410 * Xc.y() / Xc.z() + 120);
  EXPECT_LT((pinhole.Project(X) + Eigen::Vector2d(0.5, 0.5) - colmap_pixel).norm(), 1e-9);

  // Default naming: the file stem, which here repeats ("000000"): an error naming the line.
  const std::string message = ErrorOf([&] { ReadColmapTextModel(dir.string()); });
  EXPECT_CONTAINS(message, (dir / "images.txt").string());
  EXPECT_CONTAINS(message, "line 6: NAME");
  EXPECT_CONTAINS(message, "already used on line 4");
}

TEST(ColmapImport, MalformedFilesNameFileAndLine) {
  const fs::path dir = Scratch().Subdirectory("colmap_bad");
  std::ofstream(dir / "cameras.txt") << "# comment\n1 PINHOLE 640 480 500 500 320 240\n2 FISHEYE 640 480 1 2 3 4\n";
  std::ofstream(dir / "images.txt") << "1 1 0 0 0 0 0 1 1 a.png\n\n";
  std::string message = ErrorOf([&] { ReadColmapTextModel(dir.string()); });
  EXPECT_CONTAINS(message, (dir / "cameras.txt").string() + ": line 3: MODEL");
  EXPECT_CONTAINS(message, "unsupported camera model \"FISHEYE\"");

  std::ofstream(dir / "cameras.txt") << "1 PINHOLE 640 480 500 500 320\n";
  message = ErrorOf([&] { ReadColmapTextModel(dir.string()); });
  EXPECT_CONTAINS(message, "cameras.txt: line 1: PARAMS");
  EXPECT_CONTAINS(message, "expected 4 numbers");

  std::ofstream(dir / "cameras.txt") << "1 PINHOLE 40000 480 500 500 320 240\n";
  message = ErrorOf([&] { ReadColmapTextModel(dir.string()); });
  EXPECT_CONTAINS(message, "cameras.txt: line 1: WIDTH");
  EXPECT_CONTAINS(message, "expected a whole number of pixels in [1, 32768], got 40000");
  std::ofstream(dir / "cameras.txt") << "1 PINHOLE 640 0 500 500 320 240\n";
  message = ErrorOf([&] { ReadColmapTextModel(dir.string()); });
  EXPECT_CONTAINS(message, "cameras.txt: line 1: HEIGHT");

  std::ofstream(dir / "cameras.txt") << "1 PINHOLE 640 480 500 500 320 240\n";
  std::ofstream(dir / "images.txt") << "1 1 0 0 0 0 0 1 9 a.png\n\n";
  message = ErrorOf([&] { ReadColmapTextModel(dir.string()); });
  EXPECT_CONTAINS(message, "images.txt: line 1: CAMERA_ID");
  EXPECT_CONTAINS(message, "camera id 9 is not in");

  std::ofstream(dir / "images.txt") << "1 1 0 0 0 0 0 one 1 a.png\n\n";
  message = ErrorOf([&] { ReadColmapTextModel(dir.string()); });
  EXPECT_CONTAINS(message, "images.txt: line 1");
  EXPECT_CONTAINS(message, "expected \"IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME\"");
}

struct TrueCamera {
  Eigen::Matrix3d K, R;
  Eigen::Vector3d t;
};

TrueCamera RandomCamera(std::mt19937& random) {
  std::uniform_real_distribution<double> u(0, 1);
  TrueCamera camera;
  camera.K << 300 + 900 * u(random), 5 * (u(random) - 0.5), 200 + 400 * u(random), 0, 300 + 900 * u(random),
      150 + 300 * u(random), 0, 0, 1;
  camera.R = RandomRotation(random);
  camera.t = Eigen::Vector3d(u(random) - 0.5, u(random) - 0.5, 1 + 3 * u(random));
  return camera;
}

void ExpectRecovered(const Camera& read, const TrueCamera& truth) {
  // Relative 1e-9 for K (entries of hundreds of pixels), absolute 1e-9 for R and t (~1):
  // the RQ decomposition of a well-conditioned 3×3 loses a few digits of 16.
  EXPECT_LT((read.K() - truth.K).cwiseAbs().maxCoeff(), 1e-9 * truth.K.cwiseAbs().maxCoeff()) << read.name();
  EXPECT_LT((read.R() - truth.R).cwiseAbs().maxCoeff(), 1e-9) << read.name();
  EXPECT_LT((read.t() - truth.t).cwiseAbs().maxCoeff(), 1e-9) << read.name();
}

TEST(ProjectionMatrixImport, RecoversKRtFromScaledProjectionMatrices) {
  const fs::path dir = Scratch().Subdirectory("dtu");
  std::mt19937 random(11);
  std::vector<TrueCamera> truths;
  const double scales[] = {1.0, -3.7, 0.0021, -250.0, 42.0};  // P is known only up to scale and sign
  for (int i = 0; i < 5; ++i) {
    const TrueCamera truth = RandomCamera(random);
    Eigen::Matrix<double, 3, 4> Rt;
    Rt << truth.R, truth.t;
    const Eigen::Matrix<double, 3, 4> P = scales[i] * truth.K * Rt;
    char name[32];
    std::snprintf(name, sizeof(name), "pos_%03d.txt", i + 1);
    std::ofstream file(dir / name);
    if (i == 2) file << "CONTOUR\n";  // the PMVS variant
    for (int r = 0; r < 3; ++r)
      file << Number(P(r, 0)) << " " << Number(P(r, 1)) << " " << Number(P(r, 2)) << " " << Number(P(r, 3)) << "\n";
    truths.push_back(truth);
  }
  ProjectionMatrixImportOptions options;
  options.width = 1600;
  options.height = 1200;
  const std::vector<Camera> read = ReadProjectionMatrixFolder(dir.string(), options);
  ASSERT_EQ(read.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(read[i].name(), "pos_00" + std::to_string(i + 1));
    EXPECT_EQ(read[i].width(), 1600);
    ExpectRecovered(read[i], truths[i]);
  }

  // Without a given size, it comes from the image of the same stem.
  cv::imwrite((dir / "pos_001.png").string(), cv::Mat(37, 53, CV_8UC1, cv::Scalar(0)));
  for (int i = 2; i <= 5; ++i) fs::remove(dir / ("pos_00" + std::to_string(i) + ".txt"));
  const std::vector<Camera> sized = ReadProjectionMatrixFolder(dir.string());
  ASSERT_EQ(sized.size(), 1u);
  EXPECT_EQ(sized[0].width(), 53);
  EXPECT_EQ(sized[0].height(), 37);

  std::ofstream(dir / "pos_002.txt") << "1 2 3 4\n5 6 7 8\n9 10 x 12\n";
  const std::string message = ErrorOf([&] { ReadProjectionMatrixFolder(dir.string(), options); });
  EXPECT_CONTAINS(message, (dir / "pos_002.txt").string() + ": line 3");
  EXPECT_CONTAINS(message, "expected 4 numbers (row 2 of a 3×4 projection matrix)");
  std::ofstream(dir / "pos_002.txt") << "1 2 3 4\n2 4 6 8\n0 0 1 1\n";
  EXPECT_CONTAINS(ErrorOf([&] { ReadProjectionMatrixFolder(dir.string(), options); }), "non-singular");
}

TEST(ProjectionMatrixImport, ReadsMiddleburyParameterFiles) {
  const fs::path dir = Scratch().Subdirectory("middlebury");
  std::mt19937 random(5);
  std::vector<TrueCamera> truths;
  std::ofstream file(dir / "temple_par.txt");
  file << "3\n";
  for (int i = 0; i < 3; ++i) {
    truths.push_back(RandomCamera(random));
    const TrueCamera& c = truths.back();
    file << "templeR000" << i + 1 << ".png";
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) file << " " << Number(c.K(r, k));
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) file << " " << Number(c.R(r, k));
    file << " " << Number(c.t.x()) << " " << Number(c.t.y()) << " " << Number(c.t.z()) << "\n";
    cv::imwrite((dir / ("templeR000" + std::to_string(i + 1) + ".png")).string(), cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(0)));
  }
  file.close();
  const std::vector<Camera> read = ReadMiddleburyParameters((dir / "temple_par.txt").string());
  ASSERT_EQ(read.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(read[i].name(), "templeR000" + std::to_string(i + 1));
    EXPECT_EQ(read[i].width(), 64);
    EXPECT_EQ(read[i].height(), 48);
    ExpectRecovered(read[i], truths[i]);
  }
  std::ofstream(dir / "bad_par.txt") << "2\nimg1.png 1 0 0 0 1 0 0 0 1 1 0 0 0 1 0 0 0 1 0 0\n";
  const std::string message = ErrorOf([&] { ReadMiddleburyParameters((dir / "bad_par.txt").string()); });
  EXPECT_CONTAINS(message, (dir / "bad_par.txt").string() + ": line 2");
  EXPECT_CONTAINS(message, "a name and 21 numbers");
}

}  // namespace
}  // namespace subflow::vision
