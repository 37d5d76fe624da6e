// Degenerate but legal inputs keep working, with a warning where something is ignored:
// `subflow hull` on a tiny sphere dataset altered one way per test — a camera that sees
// nothing (turned away, black images, empty masks), a camera whose images are all black
// (no masks: the background-difference path), a frame where the object has left (every
// mask empty), duplicated frames, 16-bit images beside 8-bit colour and gray ones — and
// `subflow subdivide` / `check` on polygon meshes with unused vertices. Each run is
// compared with the run on the unaltered dataset.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "geometry/mesh_io.h"
#include "tests/test_support.h"
#include "vision/synthetic_render.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("degenerate_inputs_test");
  return scratch;
}

std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// A sphere seen by 5 cameras (cam00 colour, the others gray) at 64×48 pixels, 3 frames.
const fs::path& BaseDataset() {
  static const fs::path directory = [] {
    const fs::path path = Scratch().FreshPath("base");
    vision::SynthOptions options;
    options.scene.scene = "sphere";
    options.scene.frame_count = 3;
    options.scene.subdivisions = 3;
    options.rig.camera_count = 5;
    options.rig.width = 64;
    options.rig.height = 48;
    options.colour_cameras = {0};
    vision::WriteSyntheticDataset(path.string(), options);
    return path;
  }();
  return directory;
}

// A copy of the base dataset to alter.
fs::path CopyOfBase(const std::string& name) {
  const fs::path copy = Scratch().FreshPath(name);
  fs::copy(BaseDataset(), copy, fs::copy_options::recursive);
  return copy;
}

struct HullRun {
  test::CommandResult command;
  nlohmann::json report;
  geometry::TriangleMesh frame_mesh[3];
};

HullRun Hull(const fs::path& dataset, const std::string& name, const std::string& extra = "") {
  const fs::path out = Scratch().FreshPath("out_" + name);
  HullRun run;
  run.command = test::RunSubflow("hull " + Quoted(dataset) + " --out " + Quoted(out) +
                                     " --levels 1 --base-faces 80 --min-cameras 3" + extra,
                                 Scratch().path());
  if (run.command.exit_code != 0) return run;
  run.report = nlohmann::json::parse(test::ReadTextFile(out / "report.json"));
  for (int f = 0; f < 3; ++f)
    run.frame_mesh[f] = geometry::ReadMesh((out / "meshes" / ("00000" + std::to_string(f) + ".ply")).string());
  return run;
}

const HullRun& BaseRun() {
  static const HullRun run = Hull(BaseDataset(), "base");
  return run;
}

// The radius of the mesh's bounding box, averaged over the axes.
double Radius(const geometry::TriangleMesh& mesh) {
  return ((mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()) / 2).mean();
}

// The frame's hull is the sphere's: its radius within 15 % of the unaltered run's.
void ExpectSphere(const HullRun& run, int frame) {
  ASSERT_EQ(run.command.exit_code, 0) << run.command.output();
  EXPECT_NEAR(Radius(run.frame_mesh[frame]), Radius(BaseRun().frame_mesh[frame]),
              0.15 * Radius(BaseRun().frame_mesh[frame]))
      << "frame " << frame;
}

void ForEachFrameFile(const fs::path& folder, const std::function<void(const fs::path&)>& action) {
  for (const auto& entry : fs::directory_iterator(folder)) action(entry.path());
}

void Blacken(const fs::path& png) {
  cv::Mat image = cv::imread(png.string(), cv::IMREAD_UNCHANGED);
  image.setTo(0);
  cv::imwrite(png.string(), image);
}

TEST(DegenerateInputs, TheUnalteredDatasetGivesTheSphere) {
  ASSERT_EQ(BaseRun().command.exit_code, 0) << BaseRun().command.output();
  EXPECT_NEAR(Radius(BaseRun().frame_mesh[0]), 0.12, 0.02);
}

TEST(DegenerateInputs, ACameraThatSeesNothingIsExcludedWithAWarning) {
  const fs::path dataset = CopyOfBase("sees_nothing");
  const fs::path cameras = dataset / "cameras.json";
  nlohmann::json json = nlohmann::json::parse(test::ReadTextFile(cameras));
  // Turn cam03 half a turn about its own y axis (R ← diag(−1, 1, −1) R, same centre).
  nlohmann::json& camera = json["cameras"][3];
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  for (int r = 0; r < 3; ++r) {
    t[r] = camera["t"][r];
    for (int c = 0; c < 3; ++c) R(r, c) = camera["R"][r][c];
  }
  const Eigen::Vector3d centre = -R.transpose() * t;
  R = Eigen::Vector3d(-1, 1, -1).asDiagonal() * R;
  t = -R * centre;
  for (int r = 0; r < 3; ++r) {
    camera["t"][r] = t[r];
    for (int c = 0; c < 3; ++c) camera["R"][r][c] = R(r, c);
  }
  std::ofstream(cameras) << json.dump(1);
  ForEachFrameFile(dataset / "images" / "cam03", Blacken);
  ForEachFrameFile(dataset / "masks" / "cam03", Blacken);
  Blacken(dataset / "background" / "cam03.png");
  const HullRun run = Hull(dataset, "sees_nothing");
  for (int f = 0; f < 3; ++f) ExpectSphere(run, f);
  EXPECT_NE(run.command.output().find("camera \"cam03\" sees nothing of the working volume: excluded"), std::string::npos)
      << run.command.output();
}

TEST(DegenerateInputs, ACameraWithBlackImagesIsExcludedWithAWarning) {
  const fs::path dataset = CopyOfBase("black_camera");
  fs::remove_all(dataset / "masks");  // silhouettes from the background difference
  ForEachFrameFile(dataset / "images" / "cam02", Blacken);
  Blacken(dataset / "background" / "cam02.png");
  const HullRun run = Hull(dataset, "black_camera");
  for (int f = 0; f < 3; ++f) ExpectSphere(run, f);
  EXPECT_NE(run.command.output().find("camera \"cam02\" has an empty silhouette"), std::string::npos) << run.command.output();
}

TEST(DegenerateInputs, AFrameWhereTheObjectHasLeftTakesAnotherFramesHullWithAWarning) {
  const fs::path dataset = CopyOfBase("object_left");
  for (const auto& camera : fs::directory_iterator(dataset / "masks")) Blacken(camera.path() / "000001.png");
  const HullRun run = Hull(dataset, "object_left");
  ASSERT_EQ(run.command.exit_code, 0) << run.command.output();
  ExpectSphere(run, 0);
  ExpectSphere(run, 2);
  EXPECT_NE(run.command.output().find("frame 1: every camera's silhouette is empty (the object has left the working "
                                      "volume): hull of frame 0 used"),
            std::string::npos)
      << run.command.output();
  EXPECT_EQ(run.report["shape_init"]["frames"][1]["hull_from_frame"], 0) << run.report["shape_init"].dump().substr(0, 2000);
}

TEST(DegenerateInputs, DuplicatedFramesGiveTheSameHullTwice) {
  const fs::path dataset = CopyOfBase("duplicated");
  for (const char* folder : {"images", "masks"})
    for (const auto& camera : fs::directory_iterator(dataset / folder))
      fs::copy_file(camera.path() / "000000.png", camera.path() / "000001.png", fs::copy_options::overwrite_existing);
  const HullRun run = Hull(dataset, "duplicated");
  ASSERT_EQ(run.command.exit_code, 0) << run.command.output();
  // Same silhouettes → the same visual hull, exactly.
  const fs::path out = Scratch().path() / "out_duplicated" / "hull";
  const geometry::TriangleMesh hull0 = geometry::ReadMesh((out / "000000.ply").string());
  const geometry::TriangleMesh hull1 = geometry::ReadMesh((out / "000001.ply").string());
  ASSERT_EQ(hull0.vertex_count(), hull1.vertex_count());
  EXPECT_EQ((hull0.V - hull1.V).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(hull0.F == hull1.F);
  // The fitted surfaces agree to the fit's convergence: frame 1's fit starts from frame 0's
  // result, frame 0's from the simplified hull (solver/shape_init.cpp), so 1 % of the radius.
  EXPECT_LT((run.frame_mesh[1].V - run.frame_mesh[0].V).cwiseAbs().maxCoeff(), 0.01 * Radius(run.frame_mesh[0]));
  ExpectSphere(run, 2);
}

TEST(DegenerateInputs, SixteenBitImagesBesideEightBitColourAndGrayGiveTheSameHull) {
  const fs::path dataset = CopyOfBase("sixteen_bit");
  fs::remove_all(dataset / "masks");  // the images themselves decide (background difference)
  for (const char* camera : {"cam00", "cam01"}) {  // cam00 colour, cam01 gray
    auto to_16_bit = [](const fs::path& png) {
      const cv::Mat image = cv::imread(png.string(), cv::IMREAD_UNCHANGED);
      cv::Mat wide;
      image.convertTo(wide, CV_MAKETYPE(CV_16U, image.channels()), 257.0);  // v/255 = 257 v/65535
      cv::imwrite(png.string(), wide);
    };
    ForEachFrameFile(dataset / "images" / camera, to_16_bit);
    to_16_bit(dataset / "background" / (std::string(camera) + ".png"));
  }
  ASSERT_EQ(cv::imread((dataset / "images" / "cam00" / "000000.png").string(), cv::IMREAD_UNCHANGED).type(), CV_16UC3);
  const fs::path eight_bit = CopyOfBase("eight_bit");
  fs::remove_all(eight_bit / "masks");
  const HullRun wide = Hull(dataset, "sixteen_bit"), narrow = Hull(eight_bit, "eight_bit");
  ASSERT_EQ(wide.command.exit_code, 0) << wide.command.output();
  ASSERT_EQ(narrow.command.exit_code, 0) << narrow.command.output();
  // Gray values are identical up to float rounding (v / 255 vs 257 v / 65535).
  for (int f = 0; f < 3; ++f)
    EXPECT_LT((wide.frame_mesh[f].V - narrow.frame_mesh[f].V).cwiseAbs().maxCoeff(), 1e-4) << f;
  // Both runs say how the mixed formats are read, in the log and in report.json.
  const std::string mixed_wide =
      "cameras' images differ in pixel format (8-bit gray: cam02, cam03, cam04; 16-bit gray: cam01; 16-bit colour: "
      "cam00): each is read as a gray intensity in [0, 1]";
  const std::string mixed_narrow =
      "cameras' images differ in pixel format (8-bit gray: cam01, cam02, cam03, cam04; 8-bit colour: cam00)";
  const std::string sixteen = "16-bit images (cameras cam00, cam01) are read as value / 65535";
  EXPECT_NE(wide.command.output().find(mixed_wide), std::string::npos) << wide.command.output();
  EXPECT_NE(wide.command.output().find(sixteen), std::string::npos) << wide.command.output();
  EXPECT_NE(narrow.command.output().find(mixed_narrow), std::string::npos) << narrow.command.output();
  EXPECT_EQ(narrow.command.output().find("16-bit images"), std::string::npos) << narrow.command.output();
  ASSERT_EQ(wide.report["dataset"]["warnings"].size(), 2u) << wide.report["dataset"].dump();
  EXPECT_NE(wide.report["dataset"]["warnings"][0].get<std::string>().find("differ in pixel format"), std::string::npos);
}

TEST(DegenerateInputs, ACameraWhoseFramesChangePixelFormatIsNamedInAWarning) {
  const fs::path dataset = CopyOfBase("format_change");
  const fs::path frame = dataset / "images" / "cam02" / "000001.png";
  const cv::Mat gray = cv::imread(frame.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(gray.type(), CV_8UC1);
  cv::Mat colour;
  cv::merge(std::vector<cv::Mat>{gray, gray, gray}, colour);
  cv::imwrite(frame.string(), colour);
  const HullRun run = Hull(dataset, "format_change");
  for (int f = 0; f < 3; ++f) ExpectSphere(run, f);
  EXPECT_NE(run.command.output().find("camera \"cam02\": its images change pixel format within the take: 8-bit "
                                      "gray in 2 frames from 000000, 8-bit colour in 1 frame from 000001"),
            std::string::npos)
      << run.command.output();
}

TEST(DegenerateInputs, PolygonMeshesWithUnusedVerticesAreSubdividedAndValid) {
  const fs::path cube = Scratch() / "cube_quads_unused.obj";
  std::ofstream(cube) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 5 5 5\n"
                         "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  const fs::path out = Scratch() / "cube_subdivided.ply";
  const test::CommandResult run = test::RunSubflow(
      "subdivide " + Quoted(cube) + " --levels 2 --out " + Quoted(out) + " --overwrite", Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  EXPECT_NE(run.output().find("6 of 6 faces have more than 3 corners; triangulated into 12 triangles"), std::string::npos)
      << run.output();
  const geometry::TriangleMesh result = geometry::ReadMesh(out.string(), {/*require_manifold=*/false});
  EXPECT_EQ(result.face_count(), 12 * 16);
  const test::CommandResult check = test::RunSubflow("check " + Quoted(cube), Scratch().path());
  EXPECT_EQ(check.exit_code, 0) << check.output();  // unused vertices are a warning, not an error
  EXPECT_NE(check.output().find("unused"), std::string::npos) << check.output();
}

}  // namespace
}  // namespace subflow
