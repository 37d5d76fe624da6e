// Claims about the Qualisys importer: a .qca.txt written as QTM / Pose2Sim write it gives
// cameras that project known points where Pose2Sim's reading projects them (read_qca +
// calib_qca_fun: 1/64-pixel units, fov_video offset, mm → m, the π rotation about x,
// re-implemented here from Pose2Sim's code), the shared pose2sim take reads as its README
// describes, and malformed files are errors naming the camera and the attribute.
#include "vision/import_qualisys.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "tests/vision/import_test_support.h"

namespace subflow::vision {
namespace {

using test::Printed;

struct QcaValues {
  std::string serial, model = "none";
  int left = 0, top = 0, right = 0, bottom = 0;
  double r[9] = {}, x = 0, y = 0, z = 0;  // transform: rows of M, camera centre in mm
  double fu = 0, fv = 0, cu = 0, cv = 0, k1 = 0, k2 = 0, p1 = 0, p2 = 0;  // sub-pixel units, ×64
};

// The values QTM would print for `truth` (Pose2Sim's calib_toml_to_qca inverted the same way).
QcaValues FromTruth(const test::TruthCamera& truth, int left, int top, int rotation_digits) {
  QcaValues q;
  q.serial = truth.name;
  q.left = left;
  q.top = top;
  q.right = left + truth.width - 1;
  q.bottom = top + truth.height - 1;
  const Eigen::Matrix3d M = Eigen::Vector3d(1, -1, -1).asDiagonal() * truth.R;
  for (int i = 0; i < 9; ++i) q.r[i] = std::stod(Printed(M(i / 3, i % 3), rotation_digits));
  const Eigen::Vector3d centre = 1000 * truth.Centre();
  q.x = centre.x();
  q.y = centre.y();
  q.z = centre.z();
  q.fu = 64 * truth.K(0, 0);
  q.fv = 64 * truth.K(1, 1);
  q.cu = 64 * (truth.K(0, 2) + left);
  q.cv = 64 * (truth.K(1, 2) + top);
  q.k1 = 64 * truth.distortion[0];
  q.k2 = 64 * truth.distortion[1];
  q.p1 = 64 * truth.distortion[2];
  q.p2 = 64 * truth.distortion[3];
  return q;
}

std::string QcaText(const std::vector<QcaValues>& cameras) {
  std::ostringstream out;
  out << "<?xml version='1.0' encoding='ASCII'?>\n"
         "<calibration created=\"sometimes ago\" qtm-version=\"none\" source=\"test.qca.txt\" type=\"regular\">\n"
         "  <results min-max-diff=\"0.\" std-dev=\"0.\"/>\n  <cameras>\n";
  for (const QcaValues& q : cameras) {
    const std::string fov = " bottom=\"" + std::to_string(q.bottom) + "\" left=\"" + std::to_string(q.left) +
                            "\" right=\"" + std::to_string(q.right) + "\" top=\"" + std::to_string(q.top) + "\"/>\n";
    out << "    <camera active=\"1\" avg-residual=\"0.402000\" model=\"" << q.model
        << "\" point-count=\"999999999\" serial=\"" << q.serial << "\" viewrotation=\"0\">\n"
        << "      <fov_marker" << fov << "      <fov_marker_max" << fov << "      <fov_video" << fov
        << "      <fov_video_max" << fov << "      <transform";
    const char* names[] = {"r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33"};
    for (int i = 0; i < 9; ++i) out << " " << names[i] << "=\"" << Printed(q.r[i]) << "\"";
    out << " x=\"" << Printed(q.x) << "\" y=\"" << Printed(q.y) << "\" z=\"" << Printed(q.z) << "\"/>\n"
        << "      <intrinsic centerPointU=\"" << Printed(q.cu, 11) << "\" centerPointV=\"" << Printed(q.cv, 11)
        << "\" focalLengthU=\"" << Printed(q.fu, 12) << "\" focalLengthV=\"" << Printed(q.fv, 12)
        << "\" focallength=\"9.3\" radialDistortion1=\"" << Printed(q.k1) << "\" radialDistortion2=\""
        << Printed(q.k2) << "\" radialDistortion3=\"0.000000\" sensorMaxU=\"69568\" sensorMaxV=\"122816\" "
        << "sensorMinU=\"0.000000\" sensorMinV=\"0.000000\" skew=\"0.000000\" tangentalDistortion1=\""
        << Printed(q.p1) << "\" tangentalDistortion2=\"" << Printed(q.p2) << "\"/>\n    </camera>\n";
  }
  out << "  </cameras>\n</calibration>\n";
  return out.str();
}

// Pose2Sim's reading of one camera (read_qca, then calib_qca_fun's world_to_camera_persp
// and rotate_cam(ang_x = π)), then OpenCV's projection as Pose2Sim's cv2.projectPoints.
Eigen::Vector2d Pose2SimProject(const QcaValues& q, const Eigen::Vector3d& X) {
  Eigen::Matrix3d K;
  K << q.fu / 64, 0, q.cu / 64 - q.left, 0, q.fv / 64, q.cv / 64 - q.top, 0, 0, 1;
  Eigen::VectorXd D(4);
  D << q.k1 / 64, q.k2 / 64, q.p1 / 64, q.p2 / 64;
  Eigen::Matrix3d by_line;
  for (int i = 0; i < 9; ++i) by_line(i / 3, i % 3) = q.r[i];
  const Eigen::Matrix3d R_qualisys = by_line.transpose();            // "by-column to by-line"
  const Eigen::Vector3d T_qualisys = Eigen::Vector3d(q.x, q.y, q.z) / 1000;
  Eigen::Matrix3d r = R_qualisys.transpose();                        // world_to_camera_persp
  Eigen::Vector3d t = -r * T_qualisys;
  const Eigen::Matrix3d rx = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  r = rx * r;                                                        // rotate_cam(ang_x = π)
  t = rx * t;
  return test::OpenCvProject(K, r, t, D, X);
}

TEST(QualisysImport, ProjectsKnownPointsWherePose2SimsReadingDoes) {
  const std::vector<test::TruthCamera> rig =
      test::RingRig(4, 3.0, 1.9, Eigen::Vector3d::UnitZ(), 1088, 1920, 1680);
  std::vector<QcaValues> qca;
  for (std::size_t i = 0; i < rig.size(); ++i)
    qca.push_back(FromTruth(rig[i], i == 1 ? 16 : 0, i == 1 ? 8 : 0, i == 2 ? 6 : 17));  // cam03: 6 digits like QTM
  std::reverse(qca.begin(), qca.end());  // natural order of serials is restored by the reader
  const Calibration calibration = ParseQualisysCalibration(QcaText(qca), "test.qca.txt");
  EXPECT_EQ(calibration.units, "m");
  ASSERT_TRUE(calibration.up.has_value());
  EXPECT_EQ(*calibration.up, Eigen::Vector3d::UnitZ());
  const std::vector<Camera> cameras = ToCameras(calibration);
  ASSERT_EQ(cameras.size(), 4u);
  const std::vector<Eigen::Vector3d> points = test::PointsAround(Eigen::Vector3d(0, 0, 0.9), 0.8, 300);
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const QcaValues& q = qca[qca.size() - 1 - c];
    EXPECT_EQ(cameras[c].name(), q.serial);
    EXPECT_EQ(cameras[c].width(), 1088);
    EXPECT_EQ(cameras[c].height(), 1920);
    double worst = 0;
    for (const Eigen::Vector3d& X : points) worst = std::max(worst, (cameras[c].Project(X) - Pose2SimProject(q, X)).norm());
    // Exact to rounding, except cam03's rotation printed to 6 digits: Pose2Sim uses it as
    // printed, subflow its nearest rotation; ≤ 1e-6 rad × ~1700 px ≈ 2e-3 px.
    EXPECT_LT(worst, c == 2 ? 1e-2 : 1e-7) << q.serial;
    // And the truth it was written from (cam03 again within its rounding).
    double truth = 0;
    for (const Eigen::Vector3d& X : points)
      truth = std::max(truth, (cameras[c].Project(X) -
                               test::OpenCvProject(rig[c].K, rig[c].R, rig[c].t, rig[c].distortion, X)).norm());
    EXPECT_LT(truth, c == 2 ? 1e-2 : 1e-6) << q.serial;
    std::printf("    %s: max |subflow − Pose2Sim| = %.2g px, |subflow − truth| = %.2g px\n", q.serial.c_str(), worst,
                truth);
  }
}

TEST(QualisysImport, RawDistortionKeepsTheCoefficientsAsPrinted) {
  const std::vector<test::TruthCamera> rig = test::RingRig(2, 3.0, 1.9, Eigen::Vector3d::UnitZ(), 640, 480, 600);
  std::vector<QcaValues> qca = {FromTruth(rig[0], 0, 0, 17), FromTruth(rig[1], 0, 0, 17)};
  QualisysImportOptions options;
  options.raw_distortion = true;
  const Calibration raw = ParseQualisysCalibration(QcaText(qca), "test.qca.txt", options);
  EXPECT_NEAR(raw.cameras[0].distortion[0], qca[0].k1, 1e-15);
  options.raw_distortion = false;
  options.binning_factor = 2;
  qca[0].right = 2 * 640 - 1;  // a 1280-wide fov at binning 2 is 640 wide
  qca[0].bottom = 2 * 480 - 1;
  const Calibration binned = ParseQualisysCalibration(QcaText(qca), "test.qca.txt", options);
  EXPECT_EQ(binned.cameras[0].width, 640);
  EXPECT_NEAR(binned.cameras[0].K(0, 0), qca[0].fu / 128, 1e-9);
}

TEST(QualisysImport, ReadsTheSharedPose2SimTakeAsItsReadmeDescribes) {
  const std::string path = std::string(SUBFLOW_SHARED_DIR) + "/data/pose2sim_multiperson/calibration/Calib.qca.txt";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no shared pose2sim take at " << path;
  const std::vector<Camera> cameras = ToCameras(ReadQualisysCalibration(path));
  ASSERT_EQ(cameras.size(), 4u);
  for (const Camera& camera : cameras) {
    EXPECT_EQ(camera.width(), 1088);  // portrait, as the videos
    EXPECT_EQ(camera.height(), 1920);
    // Camera heights 1.7–2.1 m above the floor z = 0, 2–4 m from the treadmill at the origin.
    EXPECT_GT(camera.Center().z(), 1.5) << camera.name();
    EXPECT_LT(camera.Center().z(), 2.5) << camera.name();
    EXPECT_GT(camera.Center().head<2>().norm(), 2.0) << camera.name();
    EXPECT_LT(camera.Center().head<2>().norm(), 4.5) << camera.name();
    // The origin (the treadmill, on the floor) is in front of every camera and in its image.
    double depth = 0;
    const Eigen::Vector2d origin = camera.Project(Eigen::Vector3d::Zero(), &depth);
    EXPECT_GT(depth, 0) << camera.name();
    EXPECT_TRUE(camera.InImage(origin)) << camera.name() << " " << origin.transpose();
  }
}

TEST(QualisysImport, MalformedFilesNameTheCameraAndAttribute) {
  const std::vector<test::TruthCamera> rig = test::RingRig(2, 3.0, 1.9, Eigen::Vector3d::UnitZ(), 640, 480, 600);
  const std::string good = QcaText({FromTruth(rig[0], 0, 0, 17), FromTruth(rig[1], 0, 0, 17)});
  auto with = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    return test::ErrorOf([&] { ToCameras(ParseQualisysCalibration(text, "bad.qca.txt")); });
  };
  std::string e = with("focalLengthU=\"", "focalLengthU=\"x");
  EXPECT_NE(e.find("bad.qca.txt"), std::string::npos) << e;
  EXPECT_NE(e.find("cam01"), std::string::npos) << e;
  EXPECT_NE(e.find("intrinsic.focalLengthU"), std::string::npos) << e;
  e = with(" r11=\"", " r1=\"");
  EXPECT_NE(e.find("transform.r11"), std::string::npos) << e;
  e = with("skew=\"0.000000\"", "skew=\"12\"");
  EXPECT_NE(e.find("skew"), std::string::npos) << e;
  e = with("<cameras>", "<cameras");
  EXPECT_NE(e.find("XML"), std::string::npos) << e;
  e = with("serial=\"cam02\"", "serial=\"cam01\"");
  EXPECT_NE(e.find("unique"), std::string::npos) << e;
  // An image size beyond any sensor is refused before it becomes an int (clang's UBSan found
  // the conversion of 1e11 overflowing in BrokenInputs).
  e = with("<fov_video bottom=\"", "<fov_video bottom=\"1e11\" was=\"");
  EXPECT_NE(e.find("bad.qca.txt"), std::string::npos) << e;
  EXPECT_NE(e.find("fov_video: image height"), std::string::npos) << e;
  EXPECT_NE(e.find("whole number of pixels in [1, 32768], got 1e+11"), std::string::npos) << e;
  e = with("model=\"none\"", "model=\"Miqus M3\"");  // a marker camera is left out, not an error
  EXPECT_EQ(e, "no error");
  // A transform that is no rotation (one entry of M negated) is refused.
  const std::string r11 = good.substr(good.find("r11=\"") + 5, good.find('"', good.find("r11=\"") + 5) - good.find("r11=\"") - 5);
  e = with("r11=\"" + r11, "r11=\"" + Printed(-std::stod(r11)));
  EXPECT_NE(e.find("rotation"), std::string::npos) << e;
}

}  // namespace
}  // namespace subflow::vision
