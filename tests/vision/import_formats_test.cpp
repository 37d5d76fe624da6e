// Claims about the Pose2Sim/Anipose TOML, EasyMocap, CMU Panoptic and COLMAP binary
// importers: files written exactly as those tools write them give cameras that project
// known points where the tool's own projection puts them (cv2.projectPoints /
// cv2.fisheye.projectPoints for Anipose and EasyMocap, panutils.projectPoints for
// Panoptic, COLMAP's ImgFromCam with its half-pixel offset), re-implemented here; and bad
// files are errors naming the file and the entry.
#include <cstdint>
#include <functional>

#include <nlohmann/json.hpp>
#include <cstring>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "tests/vision/import_test_support.h"
#include "vision/import_colmap.h"
#include "vision/import_easymocap.h"
#include "vision/import_panoptic.h"
#include "vision/import_toml.h"

namespace subflow::vision {
namespace {

using test::Printed;

std::vector<test::TruthCamera> Rig() { return test::RingRig(3, 2.5, 1.6, Eigen::Vector3d::UnitZ(), 1280, 720, 1100); }
std::vector<Eigen::Vector3d> Points() { return test::PointsAround(Eigen::Vector3d(0, 0, 0.5), 0.5, 200); }

Eigen::Vector3d Rodrigues(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd axis_angle(R);
  return axis_angle.angle() * axis_angle.axis();
}

double WorstPixel(const Camera& camera, const std::function<Eigen::Vector2d(const Eigen::Vector3d&)>& reference) {
  double worst = 0;
  for (const Eigen::Vector3d& X : Points()) worst = std::max(worst, (camera.Project(X) - reference(X)).norm());
  return worst;
}

// cv2.fisheye.projectPoints written out: θ = atan r, θd = θ (1 + k1 θ² + ... + k4 θ⁸).
Eigen::Vector2d FisheyeProject(const test::TruthCamera& c, const Eigen::Vector4d& k, const Eigen::Vector3d& X) {
  const Eigen::Vector3d Xc = c.R * X + c.t;
  const Eigen::Vector2d xy = Xc.head<2>() / Xc.z();
  const double r = xy.norm(), theta = std::atan(r), t2 = theta * theta;
  const double theta_d = theta * (1 + k[0] * t2 + k[1] * t2 * t2 + k[2] * t2 * t2 * t2 + k[3] * t2 * t2 * t2 * t2);
  const Eigen::Vector2d d = xy * (theta_d / r);
  return {c.K(0, 0) * d.x() + c.K(0, 2), c.K(1, 1) * d.y() + c.K(1, 2)};
}

// Pose2Sim's toml_write: "[cam01]", size as floats, 4 distortions, fisheye = false.
std::string Pose2SimToml(const std::vector<test::TruthCamera>& rig) {
  std::ostringstream out;
  for (const auto& c : rig) {
    const Eigen::Vector3d r = Rodrigues(c.R);
    out << "[" << c.name << "]\nname = \"" << c.name << "\"\nsize = [ " << c.width << ".0, " << c.height << ".0]\n"
        << "matrix = [ [ " << Printed(c.K(0, 0)) << ", 0.0, " << Printed(c.K(0, 2)) << "], [ 0.0, " << Printed(c.K(1, 1))
        << ", " << Printed(c.K(1, 2)) << "], [ 0.0, 0.0, 1.0]]\n"
        << "distortions = [ " << Printed(c.distortion[0]) << ", " << Printed(c.distortion[1]) << ", "
        << Printed(c.distortion[2]) << ", " << Printed(c.distortion[3]) << "]\n"
        << "rotation = [ " << Printed(r[0]) << ", " << Printed(r[1]) << ", " << Printed(r[2]) << "]\n"
        << "translation = [ " << Printed(c.t[0]) << ", " << Printed(c.t[1]) << ", " << Printed(c.t[2]) << "]\n"
        << "fisheye = false\n\n";
  }
  out << "[metadata]\nadjusted = false\nerror = 0.0\n";
  return out.str();
}

TEST(TomlImport, Pose2SimCalibTomlProjectsLikeCv2ProjectPoints) {
  const auto rig = Rig();
  const Calibration calibration = ParseTomlCalibration(Pose2SimToml(rig), "Calib.toml");
  const std::vector<Camera> cameras = ToCameras(calibration);
  ASSERT_EQ(cameras.size(), rig.size());
  for (std::size_t c = 0; c < rig.size(); ++c) {
    EXPECT_EQ(cameras[c].name(), rig[c].name);
    EXPECT_EQ(cameras[c].width(), 1280);
    const double worst = WorstPixel(cameras[c], [&](const Eigen::Vector3d& X) {
      return test::OpenCvProject(rig[c].K, rig[c].R, rig[c].t, rig[c].distortion.head(4), X);
    });
    EXPECT_LT(worst, 1e-7) << rig[c].name;  // 17-digit numbers: exact to rounding
  }
}

// aniposelib CameraGroup.dump through python's toml: [cam_0] tables, trailing commas,
// 5 distortions, and a FisheyeCamera (fisheye = true, 4 coefficients), translations in mm.
TEST(TomlImport, AniposeCalibrationWithFisheyeProjectsLikeOpenCv) {
  const auto rig = Rig();
  const Eigen::Vector4d fisheye(-0.02, 0.004, -0.001, 0.0002);
  std::ostringstream out;
  for (std::size_t i = 0; i < rig.size(); ++i) {
    const auto& c = rig[i];
    const Eigen::Vector3d r = Rodrigues(c.R);
    out << "[cam_" << i << "]\nname = \"" << char('A' + i) << "\"\nsize = [ " << c.width << ", " << c.height << ",]\n"
        << "matrix = [ [ " << Printed(c.K(0, 0)) << ", 0.0, " << Printed(c.K(0, 2)) << ",], [ 0.0, " << Printed(c.K(1, 1))
        << ", " << Printed(c.K(1, 2)) << ",], [ 0.0, 0.0, 1.0,],]\n";
    if (i == 1)
      out << "distortions = [ " << Printed(fisheye[0]) << ", " << Printed(fisheye[1]) << ", " << Printed(fisheye[2])
          << ", " << Printed(fisheye[3]) << ",]\n";
    else
      out << "distortions = [ " << Printed(c.distortion[0]) << ", " << Printed(c.distortion[1]) << ", "
          << Printed(c.distortion[2]) << ", " << Printed(c.distortion[3]) << ", 0.0,]\n";
    out << "rotation = [ " << Printed(r[0]) << ", " << Printed(r[1]) << ", " << Printed(r[2]) << ",]\n"
        << "translation = [ " << Printed(1000 * c.t[0]) << ", " << Printed(1000 * c.t[1]) << ", "
        << Printed(1000 * c.t[2]) << ",]\n" << (i == 1 ? "fisheye = true\n" : "") << "\n";
  }
  out << "[metadata]\nerror = 0.31\n";
  const std::vector<Camera> cameras = ToCameras(ParseTomlCalibration(out.str(), "calibration.toml"), 0.001);
  ASSERT_EQ(cameras.size(), 3u);
  EXPECT_EQ(cameras[1].name(), "B");
  EXPECT_EQ(cameras[1].distortion_model(), DistortionModel::kFisheye);
  for (std::size_t c = 0; c < rig.size(); ++c) {
    const double worst = WorstPixel(cameras[c], [&](const Eigen::Vector3d& X) {
      return c == 1 ? FisheyeProject(rig[c], fisheye, X)
                    : test::OpenCvProject(rig[c].K, rig[c].R, rig[c].t, rig[c].distortion.head(4), X);
    });
    EXPECT_LT(worst, 1e-7) << c;
  }
}

TEST(TomlImport, MalformedFilesNameTheTableAndKey) {
  std::string text = Pose2SimToml(Rig());
  std::string bad = text;
  bad.replace(bad.find("rotation = [ "), 13, "rotation = [ \"x\", ");
  EXPECT_NE(test::ErrorOf([&] { ParseTomlCalibration(bad, "Calib.toml"); }).find("[cam01] rotation"), std::string::npos)
      << test::ErrorOf([&] { ParseTomlCalibration(bad, "Calib.toml"); });
  bad = text;
  bad.replace(bad.find("matrix"), 6, "matrx");
  EXPECT_NE(test::ErrorOf([&] { ParseTomlCalibration(bad, "Calib.toml"); }).find("matrix: missing"), std::string::npos);
  bad = text.substr(0, 20) + "= = =";
  EXPECT_NE(test::ErrorOf([&] { ParseTomlCalibration(bad, "Calib.toml"); }).find("TOML at line"), std::string::npos);
}

// EasyMocap's FileStorage.write: "%YAML:1.0\r\n---\r\n", names as quoted list items,
// matrices with 6 decimals ('{:.6f}'), Rodrigues R_ and Rot_.
std::string Mat(const std::string& key, const Eigen::MatrixXd& m) {
  std::ostringstream out;
  out << key << ": !!opencv-matrix\r\n  rows: " << m.rows() << "\r\n  cols: " << m.cols() << "\r\n  dt: d\r\n  data: [";
  for (int i = 0; i < m.size(); ++i) {
    char text[64];
    std::snprintf(text, sizeof(text), "%.6f", m(i / m.cols(), i % m.cols()));
    out << (i ? ", " : "") << text;
  }
  out << "]\r\n";
  return out.str();
}

TEST(EasyMocapImport, IntriExtriYmlProjectLikeCv2ProjectPoints) {
  const auto rig = Rig();
  std::string intri = "%YAML:1.0\r\n---\r\nnames:\r\n", extri = "%YAML:1.0\r\n---\r\nnames:\r\n";
  for (const auto& c : rig) intri += "  - \"" + c.name.substr(3) + "\"\r\n";
  extri += intri.substr(intri.find("names:\r\n") + 8);
  std::vector<test::TruthCamera> printed = rig;  // the values as EasyMocap prints them (6 decimals)
  for (std::size_t i = 0; i < rig.size(); ++i) {
    const auto& c = rig[i];
    const std::string n = c.name.substr(3);
    intri += Mat("K_" + n, c.K) + Mat("dist_" + n, c.distortion.transpose());
    if (i != 2) intri += "H_" + n + ": " + std::to_string(c.height) + "\r\nW_" + n + ": " + std::to_string(c.width) + "\r\n";
    extri += Mat("R_" + n, Rodrigues(c.R)) + Mat("Rot_" + n, c.R) + Mat("T_" + n, c.t);
    for (int k = 0; k < 9; ++k) printed[i].K(k / 3, k % 3) = std::round(c.K(k / 3, k % 3) * 1e6) / 1e6;
    for (int k = 0; k < 5; ++k) printed[i].distortion[k] = std::round(c.distortion[k] * 1e6) / 1e6;
    Eigen::Vector3d r = Rodrigues(c.R);
    for (int k = 0; k < 3; ++k) r[k] = std::round(r[k] * 1e6) / 1e6, printed[i].t[k] = std::round(c.t[k] * 1e6) / 1e6;
    printed[i].R = RodriguesToRotation(r);
  }
  Calibration calibration = ParseEasyMocapCalibration(intri, extri, "intri.yml", "extri.yml");
  ASSERT_EQ(calibration.cameras.size(), 3u);
  EXPECT_EQ(calibration.cameras[0].name, "01");
  EXPECT_EQ(calibration.cameras[2].width, 0);  // no H_/W_: taken from the media
  calibration.cameras[2].width = 1280;
  calibration.cameras[2].height = 720;
  const std::vector<Camera> cameras = ToCameras(calibration);
  for (std::size_t c = 0; c < rig.size(); ++c) {
    const double worst = WorstPixel(cameras[c], [&](const Eigen::Vector3d& X) {
      return test::OpenCvProject(printed[c].K, printed[c].R, printed[c].t, printed[c].distortion, X);
    });
    EXPECT_LT(worst, 1e-7) << c;
  }
  std::string broken = intri;
  broken.replace(broken.find("K_02"), 4, "K_2x");
  EXPECT_NE(test::ErrorOf([&] { ParseEasyMocapCalibration(broken, extri, "intri.yml", "extri.yml"); }).find("intri.yml: K_02"),
            std::string::npos);
  // A top level that is not a map: OpenCV's lookups throw cv::Exception (found by the
  // calibration fuzzer); the reader names the file and the key instead.
  // Absurd sizes are refused before OpenCV allocates them (a fuzzer's 51 GB K).
  std::string huge = intri;
  huge.replace(huge.find("rows: 3"), 7, "rows: 300000000");
  EXPECT_NE(test::ErrorOf([&] { ParseEasyMocapCalibration(huge, extri, "intri.yml", "extri.yml"); }).find("rows and cols in 1..64"),
            std::string::npos);
  const std::string sequence = "%YAML:1.0\n---\n- 1\n- 2\n";
  EXPECT_NE(test::ErrorOf([&] { ParseEasyMocapCalibration(sequence, extri, "intri.yml", "extri.yml"); }).find("intri.yml"),
            std::string::npos);
}

// panutils.projectPoints, with its in-place update of x before y is distorted.
Eigen::Vector2d PanopticProject(const test::TruthCamera& c, const Eigen::Vector3d& X_cm) {
  const Eigen::Vector3d Xc = c.R * X_cm + 100 * c.t;
  double x = Xc.x() / Xc.z(), y = Xc.y() / Xc.z();
  const Eigen::VectorXd& k = c.distortion;
  const double r = x * x + y * y;
  x = x * (1 + k[0] * r + k[1] * r * r + k[4] * r * r * r) + 2 * k[2] * x * y + k[3] * (r + 2 * x * x);
  y = y * (1 + k[0] * r + k[1] * r * r + k[4] * r * r * r) + 2 * k[3] * x * y + k[2] * (r + 2 * y * y);
  return {c.K(0, 0) * x + c.K(0, 1) * y + c.K(0, 2), c.K(1, 1) * y + c.K(1, 2)};
}

TEST(PanopticImport, CalibrationJsonProjectsLikeOpenCvAndPanutils) {
  auto rig = Rig();
  nlohmann::json root = {{"calibDataSource", "171204_pose1"}, {"cameras", nlohmann::json::array()}};
  for (auto& c : rig) {
    c.distortion[4] = 0.003;
    nlohmann::json t = nlohmann::json::array({{100 * c.t[0]}, {100 * c.t[1]}, {100 * c.t[2]}});
    root["cameras"].push_back({{"name", c.name}, {"type", "hd"}, {"resolution", {c.width, c.height}}, {"panel", 0},
                               {"node", 1}, {"K", {{c.K(0, 0), 0, c.K(0, 2)}, {0, c.K(1, 1), c.K(1, 2)}, {0, 0, 1}}},
                               {"distCoef", {c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3], c.distortion[4]}},
                               {"R", {{c.R(0, 0), c.R(0, 1), c.R(0, 2)}, {c.R(1, 0), c.R(1, 1), c.R(1, 2)}, {c.R(2, 0), c.R(2, 1), c.R(2, 2)}}},
                               {"t", t}});
  }
  const Calibration calibration = ParsePanopticCalibration(root.dump(), "calibration_171204_pose1.json");
  EXPECT_EQ(calibration.units, "cm");
  const std::vector<Camera> cameras = ToCameras(calibration, 0.01);  // cm → m
  for (std::size_t c = 0; c < rig.size(); ++c) {
    const double opencv = WorstPixel(cameras[c], [&](const Eigen::Vector3d& X) {
      return test::OpenCvProject(rig[c].K, rig[c].R, rig[c].t, rig[c].distortion, X);
    });
    EXPECT_LT(opencv, 1e-7) << c;
    // panutils' in-place update moves y' by 2 p2 (x' − x) y: below 0.05 px here.
    const double panutils = WorstPixel(cameras[c], [&](const Eigen::Vector3d& X) { return PanopticProject(rig[c], 100 * X); });
    EXPECT_LT(panutils, 0.05) << c;
    std::printf("    %s: max |subflow − OpenCV| = %.2g px, |subflow − panutils.projectPoints| = %.2g px\n",
                rig[c].name.c_str(), opencv, panutils);
  }
  root["cameras"][1]["K"] = {{1, 2}};
  EXPECT_NE(test::ErrorOf([&] { ParsePanopticCalibration(root.dump(), "c.json"); }).find("cameras[1].K"), std::string::npos);
}

template <typename T>
void Put(std::string* bytes, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  bytes->append(raw, sizeof(T));
}

// cameras.bin / images.bin as COLMAP's WriteCamerasBinary / WriteImagesBinary write them.
TEST(ColmapImport, BinaryModelProjectsLikeColmapsImgFromCam) {
  const auto rig = Rig();
  std::string cameras_bin, images_bin;
  Put<std::uint64_t>(&cameras_bin, rig.size());
  Put<std::uint64_t>(&images_bin, rig.size());
  for (std::size_t i = 0; i < rig.size(); ++i) {
    const auto& c = rig[i];
    Put<std::uint32_t>(&cameras_bin, i + 1);
    Put<std::int32_t>(&cameras_bin, 4);  // OPENCV: fx fy cx cy k1 k2 p1 p2, COLMAP pixel centres (+½)
    Put<std::uint64_t>(&cameras_bin, c.width);
    Put<std::uint64_t>(&cameras_bin, c.height);
    for (double p : {c.K(0, 0), c.K(1, 1), c.K(0, 2) + 0.5, c.K(1, 2) + 0.5, c.distortion[0], c.distortion[1],
                     c.distortion[2], c.distortion[3]})
      Put<double>(&cameras_bin, p);
    const Eigen::Quaterniond q(c.R);
    Put<std::uint32_t>(&images_bin, 10 + i);
    for (double v : {q.w(), q.x(), q.y(), q.z(), c.t[0], c.t[1], c.t[2]}) Put<double>(&images_bin, v);
    Put<std::uint32_t>(&images_bin, i + 1);
    const std::string name = c.name + "/000000.png";
    images_bin.append(name.c_str(), name.size() + 1);
    Put<std::uint64_t>(&images_bin, 1);  // one observation
    Put<double>(&images_bin, 12.5);
    Put<double>(&images_bin, 7.25);
    Put<std::uint64_t>(&images_bin, 42);
  }
  ColmapImportOptions options;
  options.name_from = ColmapImportOptions::NameFrom::kParentFolder;
  const Calibration calibration = ParseColmapBinaryModel(cameras_bin, images_bin, "sparse/0", options);
  const std::vector<Camera> cameras = ToCameras(calibration);
  for (std::size_t c = 0; c < rig.size(); ++c) {
    EXPECT_EQ(cameras[c].name(), rig[c].name);
    EXPECT_EQ(calibration.cameras[c].image_name, rig[c].name + "/000000.png");
    // COLMAP's ImgFromCam gives OpenCV's pixel + ½; subflow's pixel is COLMAP's − ½.
    const double worst = WorstPixel(cameras[c], [&](const Eigen::Vector3d& X) {
      return test::OpenCvProject(rig[c].K, rig[c].R, rig[c].t, rig[c].distortion.head(4), X);
    });
    EXPECT_LT(worst, 1e-7) << c;
  }
  EXPECT_NE(test::ErrorOf([&] { ParseColmapBinaryModel(cameras_bin.substr(0, 50), images_bin, "sparse/0"); })
                .find("sparse/0/cameras.bin"),
            std::string::npos);
  std::string unknown = cameras_bin;
  unknown[8 + 4] = 7;  // FOV model id
  EXPECT_NE(test::ErrorOf([&] { ParseColmapBinaryModel(unknown, images_bin, "sparse/0"); }).find("FOV"), std::string::npos);
}

}  // namespace
}  // namespace subflow::vision
