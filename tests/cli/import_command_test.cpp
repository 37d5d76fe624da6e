// Claims about `subflow import`: a calibration and a folder of per-camera images become a
// dataset that vision::Dataset opens, with the frames linked (not re-encoded) and
// report.json written; images at a uniform scale of the calibrated size rescale K, images a
// few pixels off it (codec padding) keep it; an
// existing dataset is not overwritten without --overwrite; a camera without images is an
// error naming it (or left out with --skip-unmatched); and the shared Qualisys take
// imports with its 4 videos.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/test_support.h"
#include "tests/vision/import_test_support.h"
#include "vision/dataset.h"

namespace subflow {
namespace {
namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("import_command_test");
  return scratch;
}

std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// `subflow import toml <dir>/Calib.toml --images <dir>/<images> --out <out>`.
std::string ImportToml(const fs::path& dir, const std::string& images, const fs::path& out) {
  return "import toml " + Quoted(dir / "Calib.toml") + " --images " + Quoted(dir / images) + " --out " + Quoted(out);
}

// A Pose2Sim Calib.toml of `rig` (exact numbers).
void WriteToml(const std::vector<test::TruthCamera>& rig, const fs::path& path) {
  std::ofstream out(path);
  for (const auto& c : rig) {
    const Eigen::AngleAxisd r(c.R);
    const Eigen::Vector3d v = r.angle() * r.axis();
    out << "[" << c.name << "]\nname = \"" << c.name << "\"\nsize = [ " << c.width << ".0, " << c.height << ".0]\n"
        << "matrix = [ [ " << test::Printed(c.K(0, 0)) << ", 0.0, " << test::Printed(c.K(0, 2)) << "], [ 0.0, "
        << test::Printed(c.K(1, 1)) << ", " << test::Printed(c.K(1, 2)) << "], [ 0.0, 0.0, 1.0]]\n"
        << "distortions = [ 0.0, 0.0, 0.0, 0.0]\nrotation = [ " << test::Printed(v[0]) << ", " << test::Printed(v[1])
        << ", " << test::Printed(v[2]) << "]\ntranslation = [ " << test::Printed(c.t[0]) << ", " << test::Printed(c.t[1])
        << ", " << test::Printed(c.t[2]) << "]\nfisheye = false\n\n";
  }
  out << "[metadata]\nadjusted = false\nerror = 0.0\n";
}

// images/<camera>/img_<i>.jpg frames of size w × h for the first `count` cameras.
void WriteImages(const std::vector<test::TruthCamera>& rig, std::size_t count, int w, int h, const fs::path& folder) {
  for (std::size_t c = 0; c < count; ++c) {
    fs::create_directories(folder / rig[c].name);
    for (int f = 0; f < 3; ++f)
      cv::imwrite((folder / rig[c].name / ("img_" + std::to_string(f + 8) + ".jpg")).string(),
                  cv::Mat(h, w, CV_8UC3, cv::Scalar(20 * f, 40, 60)));
  }
}

TEST(ImportCommand, CalibrationAndImagesBecomeADatasetThatOpens) {
  const auto rig = test::RingRig(3, 2.0, 1.5, Eigen::Vector3d::UnitZ(), 160, 120, 150);
  const fs::path dir = Scratch().Subdirectory("images");
  WriteToml(rig, dir / "Calib.toml");
  WriteImages(rig, 3, 160, 120, dir / "frames");
  const fs::path out = dir / "dataset";
  const test::CommandResult run = test::RunSubflow(
      ImportToml(dir, "frames", out) + " --bounds -0.5,-0.5,0,0.5,0.5,1 --frames 2",
      dir);
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const vision::Dataset dataset(out.string());
  EXPECT_EQ(dataset.camera_count(), 3);
  EXPECT_EQ(dataset.frame_count(), 2);
  EXPECT_EQ(dataset.bounds().max.z(), 1.0);
  // Linked, not re-encoded: frame 1 of cam02 is the link to its second image (natural order).
  const fs::path frame = out / "images" / "cam02" / "000001.jpg";
  ASSERT_TRUE(fs::is_symlink(frame));
  EXPECT_EQ(fs::read_symlink(frame).filename(), "img_9.jpg");
  EXPECT_EQ(dataset.Image(1, 1).cols, 160);
  const nlohmann::json report = nlohmann::json::parse(test::ReadTextFile(out / "report.json"));
  EXPECT_EQ(report["command"], "import");
  EXPECT_EQ(report["cameras"].size(), 3u);
  EXPECT_EQ(report["bounds"]["origin"], "given (--bounds)");
  for (std::size_t c = 0; c < rig.size(); ++c)
    EXPECT_LT((dataset.camera(c).Center() - rig[c].Centre()).norm(), 1e-9);

  // Not again without --overwrite; with it, the dataset is replaced.
  const test::CommandResult again = test::RunSubflow(ImportToml(dir, "frames", out), dir);
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.err.find("refusing to overwrite"), std::string::npos) << again.output();
  const test::CommandResult replaced = test::RunSubflow(ImportToml(dir, "frames", out) + " --overwrite --link copy", dir);
  ASSERT_EQ(replaced.exit_code, 0) << replaced.output();
  EXPECT_FALSE(fs::is_symlink(out / "images" / "cam02" / "000001.jpg"));
  EXPECT_EQ(vision::Dataset(out.string()).frame_count(), 3);
}

TEST(ImportCommand, HalfSizeImagesRescaleTheIntrinsics) {
  const auto rig = test::RingRig(2, 2.0, 1.5, Eigen::Vector3d::UnitZ(), 160, 120, 150);
  const fs::path dir = Scratch().Subdirectory("half");
  WriteToml(rig, dir / "Calib.toml");
  WriteImages(rig, 2, 80, 60, dir / "frames");
  const test::CommandResult run = test::RunSubflow(ImportToml(dir, "frames", dir / "d"), dir);
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const vision::Dataset dataset((dir / "d").string());
  EXPECT_EQ(dataset.camera(0).width(), 80);
  EXPECT_NEAR(dataset.camera(0).K()(0, 0), rig[0].K(0, 0) / 2, 1e-12);
  EXPECT_NEAR(dataset.camera(0).K()(0, 2), (rig[0].K(0, 2) + 0.5) / 2 - 0.5, 1e-12);  // pixel centres
  EXPECT_NE(run.out.find("intrinsics scaled by 0.5"), std::string::npos) << run.output();
}

// A video coded in 16-pixel blocks: the calibration says 1088 columns, the re-encoded video
// has 1080 (Pose2Sim's single-person demo). Within 15 pixels the frames are the calibrated
// grid cut or padded at the right and bottom edges: K is kept. Beyond, and not a uniform
// scale, it is an error naming the image and the size.
TEST(ImportCommand, FramesCutByCodecPaddingKeepTheIntrinsics) {
  const auto rig = test::RingRig(2, 2.0, 1.5, Eigen::Vector3d::UnitZ(), 168, 120, 150);
  const fs::path dir = Scratch().Subdirectory("padding");
  WriteToml(rig, dir / "Calib.toml");
  WriteImages(rig, 2, 160, 120, dir / "frames");
  const test::CommandResult run = test::RunSubflow(ImportToml(dir, "frames", dir / "d"), dir);
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const vision::Dataset dataset((dir / "d").string());
  EXPECT_EQ(dataset.camera(0).width(), 160);
  EXPECT_EQ(dataset.camera(0).height(), 120);
  EXPECT_EQ(dataset.camera(0).K(), rig[0].K);
  EXPECT_NE(run.out.find("codec block padding"), std::string::npos) << run.output();

  WriteImages(rig, 2, 148, 120, dir / "narrow");
  const test::CommandResult narrow = test::RunSubflow(ImportToml(dir, "narrow", dir / "e"), dir);
  EXPECT_EQ(narrow.exit_code, 1);
  EXPECT_NE(narrow.err.find("img_8.jpg: size: expected 168×120"), std::string::npos) << narrow.output();
  EXPECT_NE(narrow.err.find("got 148×120"), std::string::npos) << narrow.output();
  EXPECT_FALSE(fs::exists(dir / "e" / "cameras.json"));
}

TEST(ImportCommand, ACameraWithoutImagesIsAnErrorUnlessSkipped) {
  const auto rig = test::RingRig(3, 2.0, 1.5, Eigen::Vector3d::UnitZ(), 160, 120, 150);
  const fs::path dir = Scratch().Subdirectory("missing");
  WriteToml(rig, dir / "Calib.toml");
  WriteImages(rig, 2, 160, 120, dir / "frames");
  const std::string base = ImportToml(dir, "frames", dir / "d");
  const test::CommandResult run = test::RunSubflow(base, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("cam03"), std::string::npos) << run.output();
  EXPECT_FALSE(fs::exists(dir / "d" / "cameras.json"));
  const test::CommandResult skipped = test::RunSubflow(base + " --skip-unmatched", dir);
  ASSERT_EQ(skipped.exit_code, 0) << skipped.output();
  EXPECT_EQ(vision::Dataset((dir / "d").string()).camera_count(), 2);
}

TEST(ImportCommand, ImportsTheSharedQualisysTake) {
  const fs::path take = fs::path(SUBFLOW_SHARED_DIR) / "data" / "pose2sim_multiperson";
  if (!fs::exists(take / "calibration" / "Calib.qca.txt")) GTEST_SKIP() << "no shared pose2sim take at " << take;
  const fs::path dir = Scratch().Subdirectory("qualisys");
  const test::CommandResult run =
      test::RunSubflow("import qualisys " + Quoted(take / "calibration" / "Calib.qca.txt") + " --videos " +
                           Quoted(take / "videos") + " --out " + Quoted(dir / "d"),
                       dir);
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const vision::Dataset dataset((dir / "d").string());
  EXPECT_EQ(dataset.camera_count(), 4);
  EXPECT_EQ(dataset.frame_count(), 100);
  ASSERT_TRUE(dataset.fps().has_value());
  EXPECT_NEAR(*dataset.fps(), 60, 0.1);
  const cv::Mat frame = dataset.Image(0, 0);  // decoded size = calibrated size
  EXPECT_EQ(frame.cols, 1088);
  EXPECT_EQ(frame.rows, 1920);
  // The derived volume lies above the floor and holds the treadmill at the origin.
  EXPECT_EQ(dataset.bounds().min.z(), 0.0);
  EXPECT_TRUE(dataset.bounds().Contains(Eigen::Vector3d(0, 0, 1)));
}

}  // namespace
}  // namespace subflow
