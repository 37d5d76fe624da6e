// `subflow render` on a small synthetic dataset whose ground-truth meshes serve as the
// result (so the surface must land exactly on the masks): every kind of picture is
// checked for its content — where the surface is, the colour bar's colours and range,
// the outline on the object's boundary, texture taken from the images, the MP4's frames.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "geometry/mesh_io.h"
#include "output/colour_scale.h"
#include "output/result_writer.h"
#include "tests/test_support.h"
#include "vision/dataset.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;
using test::RunSubflow;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("render_command");
  return scratch;
}
std::string Quote(const fs::path& path) { return "'" + path.string() + "'"; }

// 4 cameras (2 colour), 3 frames, 160×120; the result = the ground truth, flow = its motion.
const fs::path& Dataset() {
  static const fs::path dataset = [] {
    const fs::path path = Scratch() / "blob";
    const test::CommandResult run = RunSubflow(
        "synth blob --out " + Quote(path) + " --cameras 4 --frames 3 --width 160 --height 120 --subdivisions 4",
        Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return path;
  }();
  return dataset;
}
const fs::path& Result() {
  static const fs::path result = [] {
    const fs::path path = Scratch() / "result";
    std::vector<geometry::Positions> positions;
    geometry::Faces faces;
    for (int f = 0; f < 3; ++f) {
      const geometry::TriangleMesh mesh =
          geometry::ReadMesh((Dataset() / "groundtruth" / "mesh" / (vision::FrameName(f) + ".ply")).string());
      positions.push_back(mesh.V);
      faces = mesh.F;
    }
    output::WriteResultMeshes(path.string(), 0, faces, positions);
    output::WriteJsonFile((path / "report.json").string(), {{"dataset", {{"directory", Dataset().string()}}}});
    return path;
  }();
  return result;
}
// Runs render once for the tests that share its pictures.
const fs::path& Pictures() {
  static const fs::path pictures = [] {
    const fs::path out = Scratch() / "pictures";
    const test::CommandResult run =
        RunSubflow("render " + Quote(Result()) + " --out " + Quote(out) + " --views 4 --view-width 320 --view-height 240 --mp4",
                   Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return out;
  }();
  return pictures;
}
nlohmann::json Report() { return nlohmann::json::parse(test::ReadTextFile(Pictures() / "report.json")); }

cv::Mat Read(const fs::path& path) {
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
  EXPECT_FALSE(image.empty()) << path;
  return image;
}
// Pixels of `picture` (its left width × height part) that are not the white background.
cv::Mat NonWhite(const cv::Mat& picture, int width, int height) {
  cv::Mat part = picture(cv::Rect(0, 0, width, height)), mask;
  cv::inRange(part, cv::Scalar(250, 250, 250), cv::Scalar(255, 255, 255), mask);
  return 255 - mask;
}
double IoU(const cv::Mat& a, const cv::Mat& b) {
  return cv::countNonZero(a & b) / std::max(1.0, static_cast<double>(cv::countNonZero(a | b)));
}

TEST(RenderCommand, FlowPicturesCoverTheObjectWhereItsMaskIs) {
  const vision::Dataset dataset(Dataset().string());
  for (int c = 0; c < dataset.camera_count(); ++c)
    for (int frame : {0, 1, 2}) {
      const cv::Mat picture = Read(Pictures() / "flow" / dataset.camera(c).name() / (vision::FrameName(frame) + ".png"));
      ASSERT_GT(picture.cols, 160);  // the colour bar's margin
      // The ground truth rendered where the renderer of the dataset drew it: masks agree
      // up to anti-aliased boundary pixels.
      EXPECT_GT(IoU(NonWhite(picture, 160, 120), dataset.Mask(c, frame)), 0.95) << dataset.camera(c).name() << " " << frame;
    }
}

TEST(RenderCommand, ColourBarSpansTheFlowsRangeInViridis) {
  // The flow's range, computed here from the PLYs' vx vy vz (the last frame shows the
  // motion into it, so frames 0 and 1 hold every magnitude).
  double low = 1e30, high = 0;
  for (int frame : {0, 1}) {
    geometry::VertexProperties properties;
    geometry::ReadMesh((Result() / "meshes" / (vision::FrameName(frame) + ".ply")).string(), {}, &properties);
    const Eigen::VectorXd magnitude = (properties.values["vx"].array().square() + properties.values["vy"].array().square() +
                                       properties.values["vz"].array().square()).sqrt();
    low = std::min(low, magnitude.minCoeff());
    high = std::max(high, magnitude.maxCoeff());
  }
  const nlohmann::json report = Report();
  const nlohmann::json& scale = report["colour_scales"]["flow"];
  EXPECT_NEAR(scale["min"].get<double>(), low, 1e-7 * high);  // float magnitudes
  EXPECT_NEAR(scale["max"].get<double>(), high, 1e-7 * high);
  EXPECT_EQ(scale["units"], "mm/frame");
  EXPECT_EQ(scale["display_factor"], 1000.0);
  EXPECT_FALSE(report["colour_scales"].contains("nonrigid"));  // the result has no non-rigid flow
  int checked = 0;
  for (const nlohmann::json& picture : report["pictures"]) {
    if (picture["kind"] != "flow" || picture["path"].get<std::string>().rfind("flow/", 0) != 0) continue;
    const cv::Mat image = Read(Pictures() / picture["path"].get<std::string>());
    const nlohmann::json& bar = picture["colour_bar"];
    const int x = (bar["left"].get<int>() + bar["right"].get<int>()) / 2;
    const auto& table = output::ColourScale::Table();
    const cv::Vec3b top = image.at<cv::Vec3b>(bar["top"].get<int>(), x), bottom = image.at<cv::Vec3b>(bar["bottom"].get<int>(), x);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(top[2 - k], table[255][k], 2) << picture["path"];  // BGR picture, RGB table
      EXPECT_NEAR(bottom[2 - k], table[0][k], 2) << picture["path"];
    }
    ++checked;
  }
  EXPECT_EQ(checked, 12);  // 4 cameras × 3 frames
}

TEST(RenderCommand, OverlayOutlineLiesOnTheObjectsBoundary) {
  const vision::Dataset dataset(Dataset().string());
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const cv::Mat overlay = Read(Pictures() / "overlay" / dataset.camera(c).name() / "000001.png");
    cv::Mat outline;
    cv::inRange(overlay(cv::Rect(0, 0, 160, 120)), cv::Scalar(250, 0, 250), cv::Scalar(255, 5, 255), outline);
    const cv::Mat mask = dataset.Mask(c, 1);
    cv::Mat boundary, inner, outer;
    cv::erode(mask, inner, cv::Mat());
    cv::dilate(mask, outer, cv::Mat());
    cv::dilate(outer - inner, boundary, cv::Mat());  // the mask's boundary, ±2 px
    const int outline_pixels = cv::countNonZero(outline);
    // A closed curve around the object: at least its perimeter's worth of pixels…
    double perimeter = 0;
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(mask.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    for (const auto& contour : contours) perimeter += cv::arcLength(contour, true);
    EXPECT_GT(outline_pixels, 0.8 * perimeter) << dataset.camera(c).name();
    // …all on the boundary.
    EXPECT_GE(cv::countNonZero(outline & boundary), 0.98 * outline_pixels) << dataset.camera(c).name();
    // Inside the outline the image shows through the shading: not the flat picture colour.
    EXPECT_EQ(overlay.size(), Read(Pictures() / "flow" / dataset.camera(c).name() / "000001.png").size());
  }
  const cv::Mat sheet = Read(Pictures() / "contact_sheet" / "000001.png");
  EXPECT_EQ(sheet.cols, 2 * 160);  // 4 cameras: 2 × 2 tiles of the overlays' width
  EXPECT_EQ(sheet.rows, 2 * 120);
}

TEST(RenderCommand, NewViewsShowTheWholeObjectAndItsTexture) {
  int turntable = 0, textured = 0;
  const nlohmann::json report = Report();
  for (const nlohmann::json& picture : report["pictures"]) {
    const std::string kind = picture["kind"];
    const std::string path = picture["path"];
    if (path.rfind("turntable/", 0) == 0) {
      // The bounding sphere fills 80 % of the smaller side: the blob covers ≈ π 0.4² · 3/4 of the view.
      const double share = picture["surface_pixels"].get<double>() / picture["pixels"].get<double>();
      EXPECT_GT(share, 0.2) << path;
      EXPECT_LT(share, 0.6) << path;
      const cv::Mat image = Read(Pictures() / path);
      EXPECT_NEAR(cv::countNonZero(NonWhite(image, 320, 240)), picture["surface_pixels"].get<double>(), 0.02 * 320 * 240);
      ++turntable;
    }
    if (kind == "textured") {
      const cv::Mat image = Read(Pictures() / path);
      const cv::Mat surface = NonWhite(image, 320, 240);
      // Texture from the images: strong contrast on the surface (the procedural cells),
      // little of the gray used where no camera sees the surface.
      cv::Scalar mean, deviation;
      cv::Mat gray;
      cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
      cv::meanStdDev(gray, mean, deviation, surface);
      EXPECT_GT(deviation[0], 20.0) << path;
      cv::Mat fallback;
      cv::inRange(image, cv::Scalar(152, 152, 152), cv::Scalar(154, 154, 154), fallback);
      EXPECT_LT(cv::countNonZero(fallback), 0.1 * cv::countNonZero(surface)) << path;
      ++textured;
    }
  }
  EXPECT_EQ(turntable, 4);  // flow only: the result has no non-rigid flow
  EXPECT_EQ(textured, 4);
}

TEST(RenderCommand, Mp4HoldsEveryFrameOfEachCamera) {
  cv::VideoCapture video((Pictures() / "mp4" / "cam00.mp4").string());
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  cv::Mat image;
  while (video.read(image)) {
    EXPECT_GE(image.cols, 160);
    ++frames;
  }
  EXPECT_EQ(frames, 3);
}

TEST(RenderCommand, WithoutDatasetDrawsTheTurntableOnly) {
  const fs::path out = Scratch().FreshPath("no_dataset");
  const test::CommandResult run =
      RunSubflow("render " + Quote(Result()) + " --no-dataset --views 3 --out " + Quote(out), Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const nlohmann::json report = nlohmann::json::parse(test::ReadTextFile(out / "report.json"));
  ASSERT_EQ(report["pictures"].size(), 3u);
  for (const nlohmann::json& picture : report["pictures"]) {
    EXPECT_EQ(picture["path"].get<std::string>().rfind("turntable/flow_000001_view", 0), 0u) << picture["path"];
    EXPECT_GT(picture["surface_pixels"].get<int>(), 0);
  }
  EXPECT_FALSE(fs::exists(out / "overlay"));
}

// eval --error-maps writes result folders whose vertex properties render --colour-by
// pictures: here the view counts of the true surface (the result is the truth, so its
// errors are 0).
TEST(RenderCommand, ColoursByAVertexPropertyOfTheErrorMaps) {
  const fs::path maps = Scratch().FreshPath("maps");
  const test::CommandResult eval =
      RunSubflow("eval " + Quote(Dataset()) + " " + Quote(Result()) + " --error-maps " + Quote(maps), Scratch().path());
  ASSERT_EQ(eval.exit_code, 0) << eval.output();
  geometry::VertexProperties properties;
  geometry::ReadMesh((maps / "truth" / "meshes" / "000001.ply").string(), {}, &properties);
  ASSERT_TRUE(properties.values.count("views") && properties.values.count("error"));
  EXPECT_LT(properties.values["error"].cwiseAbs().maxCoeff(), 1e-6);
  const double most_views = properties.values["views"].maxCoeff();
  EXPECT_GE(most_views, 2.0);
  EXPECT_LE(most_views, 4.0);

  const fs::path out = Scratch().FreshPath("views");
  const test::CommandResult run = RunSubflow("render " + Quote(maps / "truth") + " --out " + Quote(out) +
                                                 " --colour-by views --no-textured --no-overlays --views 0",
                                             Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const nlohmann::json report = nlohmann::json::parse(test::ReadTextFile(out / "report.json"));
  ASSERT_TRUE(report["colour_scales"].contains("views"));
  EXPECT_FALSE(report["colour_scales"].contains("flow"));
  EXPECT_GE(report["colour_scales"]["views"]["max"].get<double>(), most_views);
  EXPECT_TRUE(fs::exists(out / "views" / vision::Dataset(Dataset().string()).camera(0).name() / "000001.png"));

  const test::CommandResult missing = RunSubflow("render " + Quote(maps / "truth") + " --out " +
                                                     Quote(Scratch().FreshPath("missing")) + " --colour-by nosuch",
                                                 Scratch().path());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("vertex property nosuch"), std::string::npos) << missing.output();
}

TEST(RenderCommand, RefusesFramesOutsideTheResultAndExistingOutput) {
  const test::CommandResult bad = RunSubflow(
      "render " + Quote(Result()) + " --out " + Quote(Scratch().FreshPath("bad")) + " --frames 7", Scratch().path());
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("--frames: frame 7: not in the result"), std::string::npos) << bad.output();
  const test::CommandResult again = RunSubflow("render " + Quote(Result()) + " --out " + Quote(Pictures()), Scratch().path());
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.err.find("not empty"), std::string::npos) << again.output();
}

}  // namespace
}  // namespace subflow
