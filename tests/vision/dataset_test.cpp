// Claims about vision::Dataset and DatasetWriter: the sample dataset reads with our
// convention, a written dataset reads back identically, frames are held in a bounded
// window, and every malformed input is an error naming the file, field and expectation.
#include "vision/dataset.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>

#include "core/error.h"
#include "geometry/mesh_io.h"
#include "vision/dataset_writer.h"
#include "tests/test_support.h"

namespace subflow::vision {
namespace {
namespace fs = std::filesystem;

const std::string kBlob = SUBFLOW_SHARED_DIR "/data/blob";

// This run's scratch directory (removed at exit); each test works below it.
const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("dataset_test");
  return scratch;
}

// A camera at `center` looking at the origin, +y of the image pointing down the world −z.
Camera LookAt(const std::string& name, const Eigen::Vector3d& center, int width, int height, double f,
              const Eigen::VectorXd& distortion = Eigen::VectorXd()) {
  const Eigen::Vector3d z = (-center).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d(0, 0, 1)).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x;
  R.row(1) = y;
  R.row(2) = z;
  Eigen::Matrix3d K;
  K << f, 0, (width - 1) / 2.0 + 0.123, 0, f * 1.01, (height - 1) / 2.0 - 0.071, 0, 0, 1;
  return Camera(name, width, height, K, R, -R * center, distortion);
}

std::vector<Camera> SmallRig() {
  Eigen::VectorXd distortion(5);
  distortion << -0.11, 0.013, 0.0004, -0.0002, 0.001;
  return {LookAt("left", {-1.0, -1.3, 0.31}, 16, 12, 14.3, distortion),
          LookAt("right", {1.1, -1.2, 0.29}, 16, 12, 15.7),
          LookAt("top", {0.1, 0.2, 1.9}, 20, 10, 13.1)};
}

cv::Mat RandomImage(int width, int height, int type, unsigned seed) {
  cv::Mat image(height, width, type);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

// Writes a valid dataset of SmallRig() with `frames` frames: camera 0 colour 8-bit,
// camera 1 gray 16-bit, camera 2 gray 8-bit; masks and backgrounds for every camera.
void WriteSmallDataset(const fs::path& dir, int frames, bool with_frame_count = true) {
  DatasetInfo info;
  info.fps = 29.97;
  if (with_frame_count) info.frame_count = frames;
  info.units = "meters";
  info.bounds = Bounds{Eigen::Vector3d(-0.3, -0.2, -0.1), Eigen::Vector3d(0.3, 0.25, 0.4)};
  const std::vector<Camera> cameras = SmallRig();
  DatasetWriter writer(dir.string(), cameras, info, /*overwrite=*/true);
  const int types[3] = {CV_8UC3, CV_16UC1, CV_8UC1};
  for (int c = 0; c < 3; ++c) {
    for (int f = 0; f < frames; ++f) {
      writer.WriteImage(c, f, RandomImage(cameras[c].width(), cameras[c].height(), types[c], 100 * c + f));
      writer.WriteMask(c, f, RandomImage(cameras[c].width(), cameras[c].height(), CV_8UC1, 1000 + 100 * c + f) > 128);
    }
    writer.WriteBackground(c, RandomImage(cameras[c].width(), cameras[c].height(), types[c], 7 + c));
  }
}

// The message of the subflow::Error thrown by `action`, or "no error".
template <typename Action>
std::string ErrorOf(Action action) {
  try {
    action();
  } catch (const Error& e) {
    std::printf("    message: %s\n", e.what());
    return e.what();
  }
  return "no error";
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

template <typename Edit>
void EditJson(const fs::path& path, Edit edit) {
  nlohmann::json root;
  std::ifstream(path) >> root;
  edit(root);
  std::ofstream(path) << root.dump(1);
}

void ReplaceInFile(const fs::path& path, const std::string& from, const std::string& to) {
  std::string text = test::ReadTextFile(path);
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  std::ofstream(path) << text;
}

TEST(Dataset, ReadsTheBlobSample) {
  const Dataset dataset(kBlob);
  EXPECT_EQ(dataset.camera_count(), 10);
  EXPECT_EQ(dataset.frame_count(), 24);
  EXPECT_EQ(dataset.fps().value_or(0), 60);
  EXPECT_EQ(dataset.units(), "meters");
  EXPECT_TRUE(dataset.bounds_from_file());
  EXPECT_EQ(dataset.bounds().min, Eigen::Vector3d(-0.1386, -0.1345, -0.1242));
  EXPECT_TRUE(dataset.has_masks() && dataset.has_background() && dataset.has_groundtruth());
  EXPECT_FALSE(dataset.has_videos());
  EXPECT_EQ(dataset.CameraIndex("cam04"), 4);
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const bool colour = c == 0 || c == 4;
    for (int f : {0, 23}) {
      const cv::Mat image = dataset.Image(c, f);
      EXPECT_EQ(image.channels(), colour ? 3 : 1) << dataset.camera(c).name();
      const cv::Mat gray = dataset.Gray(c, f);
      ASSERT_EQ(gray.type(), CV_32FC1);
      ASSERT_EQ(gray.cols, 320);
      ASSERT_EQ(gray.rows, 240);
      double low, high;
      cv::minMaxLoc(gray, &low, &high);
      EXPECT_GE(low, 0.0);
      EXPECT_LE(high, 1.0);
      EXPECT_GT(high, 0.3) << "a textured, lit object is in view";
    }
  }
  // Gray of a colour frame is OpenCV's weighted sum 0.114 B + 0.587 G + 0.299 R, scaled
  // to [0, 1]; computed here in double, so the tolerance is float rounding.
  const cv::Mat colour = dataset.Image(0, 5), gray = dataset.Gray(0, 5);
  double worst = 0;
  for (int y = 0; y < colour.rows; ++y)
    for (int x = 0; x < colour.cols; ++x) {
      const cv::Vec3b bgr = colour.at<cv::Vec3b>(y, x);
      const double expected = (0.114 * bgr[0] + 0.587 * bgr[1] + 0.299 * bgr[2]) / 255;
      worst = std::max(worst, std::abs(gray.at<float>(y, x) - expected));
    }
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(dataset.Background(3).size(), cv::Size(320, 240));
  EXPECT_EQ(dataset.GroundTruthMeshPath(7), kBlob + "/groundtruth/mesh/000007.ply");
}

TEST(Dataset, BlobGroundTruthProjectsOntoItsMasks) {
  const Dataset dataset(kBlob);
  const geometry::TriangleMesh mesh = geometry::ReadMesh(dataset.GroundTruthMeshPath(0));
  ASSERT_EQ(mesh.vertex_count(), 10242);
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const Camera& camera = dataset.camera(c);
    const cv::Mat mask = dataset.Mask(c, 0);
    int on_mask = 0;
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      const Eigen::Vector2d p = camera.Project(mesh.V.row(v).transpose());
      const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
      bool hit = false;  // a non-zero mask pixel within ±1 px
      for (int dy = -1; dy <= 1 && !hit; ++dy)
        for (int dx = -1; dx <= 1 && !hit; ++dx)
          hit = x + dx >= 0 && y + dy >= 0 && x + dx < mask.cols && y + dy < mask.rows &&
                mask.at<uchar>(y + dy, x + dx) != 0;
      on_mask += hit;
    }
    // Silhouette vertices sit on the mask border; ±1 px absorbs the rasterization of the
    // independent renderer. A convention error of a whole pixel or a flipped axis fails.
    EXPECT_GE(on_mask, 0.999 * mesh.vertex_count()) << camera.name();
    std::printf("    %s: %.4f of the vertices on the mask (±1 px)\n", camera.name().c_str(),
                static_cast<double>(on_mask) / mesh.vertex_count());
  }
}

TEST(Dataset, DerivedWorkingVolumeContainsTheBlob) {
  const Dataset dataset(kBlob);
  const Bounds derived = EstimateWorkingVolume(dataset.cameras());
  const Bounds& truth = dataset.bounds();
  EXPECT_TRUE(derived.Contains(truth.min) && derived.Contains(truth.max))
      << derived.min.transpose() << " / " << derived.max.transpose();
  // The region seen by ≥ 8 of 10 cameras of a ring at 0.6 m with ±21° half-angles is
  // ~0.45 m wide: the derived box must not be much more than that.
  EXPECT_LT(derived.Diagonal(), 1.2);
  std::printf("    derived bounds min (%.4f %.4f %.4f) max (%.4f %.4f %.4f), diagonal %.3f m\n", derived.min.x(),
              derived.min.y(), derived.min.z(), derived.max.x(), derived.max.y(), derived.max.z(),
              derived.Diagonal());
  // Two cameras on the y axis looking away from each other see nothing in common.
  const Camera a = LookAt("a", {0, -1, 0}, 16, 12, 14);
  const Eigen::Matrix3d turned = Eigen::Vector3d(-1, 1, -1).asDiagonal() * a.R();  // 180° about its y
  const Camera b("b", 16, 12, a.K(), turned, -turned * Eigen::Vector3d(0, -1.2, 0));
  const std::string message = ErrorOf([&] { EstimateWorkingVolume({a, b}, {}, "rig.json"); });
  EXPECT_CONTAINS(message, "rig.json: bounds");
  EXPECT_CONTAINS(message, "seen by 2 of the 2 cameras");
}

TEST(Dataset, RoundTripGivesIdenticalCamerasAndPixels) {
  const fs::path dir = Scratch().Subdirectory("round_trip");
  WriteSmallDataset(dir, 3);
  const std::vector<Camera> written = SmallRig();
  const Dataset dataset(dir.string());
  ASSERT_EQ(dataset.camera_count(), 3);
  EXPECT_EQ(dataset.frame_count(), 3);
  EXPECT_EQ(*dataset.fps(), 29.97);
  for (int c = 0; c < 3; ++c) {
    const Camera& read = dataset.camera(c);
    EXPECT_EQ(read.name(), written[c].name());
    EXPECT_EQ(read.width(), written[c].width());
    EXPECT_EQ(read.height(), written[c].height());
    // Exact: the JSON writer prints the shortest decimal that reads back to the same double.
    EXPECT_EQ(read.K(), written[c].K());
    EXPECT_EQ(read.R(), written[c].R());
    EXPECT_EQ(read.t(), written[c].t());
    EXPECT_EQ(read.distortion(), written[c].distortion());
    const int types[3] = {CV_8UC3, CV_16UC1, CV_8UC1};
    for (int f = 0; f < 3; ++f) {
      const cv::Mat expected = RandomImage(read.width(), read.height(), types[c], 100 * c + f);
      const cv::Mat image = dataset.Image(c, f);
      ASSERT_EQ(image.type(), types[c]);
      EXPECT_EQ(cv::norm(image, expected, cv::NORM_INF), 0.0);
      const cv::Mat mask_expected =
          RandomImage(read.width(), read.height(), CV_8UC1, 1000 + 100 * c + f) > 128;
      EXPECT_EQ(cv::norm(dataset.Mask(c, f), mask_expected, cv::NORM_INF), 0.0);
    }
    EXPECT_EQ(cv::norm(dataset.Background(c), RandomImage(read.width(), read.height(), types[c], 7 + c),
                       cv::NORM_INF),
              0.0);
  }
  // 16-bit gray is scaled by 1/65535.
  const cv::Mat raw16 = dataset.Image(1, 2);
  EXPECT_FLOAT_EQ(dataset.Gray(1, 2).at<float>(3, 4), raw16.at<uint16_t>(3, 4) / 65535.0f);
  // Ground truth goes through geometry::WriteMesh (float PLY): same vertices as floats.
  geometry::TriangleMesh mesh;
  mesh.V.resize(3, 3);
  mesh.V << 0.1, 0.2, 0.3, 1.1, 0.2, 0.3, 0.1, 1.2, 0.3;
  mesh.F.resize(1, 3);
  mesh.F << 0, 1, 2;
  DatasetWriter gt_writer(dir.string(), written, DatasetInfo{{}, 1, {}, ""}, /*overwrite=*/true);
  for (int c = 0; c < 3; ++c) gt_writer.WriteImage(c, 0, RandomImage(written[c].width(), written[c].height(), CV_8UC1, 1));
  gt_writer.WriteGroundTruthMesh(0, mesh);
  const Dataset with_gt(dir.string());
  EXPECT_TRUE(with_gt.has_groundtruth());
  EXPECT_FALSE(with_gt.bounds_from_file());
  const geometry::TriangleMesh read_mesh = geometry::ReadMesh(with_gt.GroundTruthMeshPath(0), {false});
  EXPECT_EQ(read_mesh.F, mesh.F);
  EXPECT_LT((read_mesh.V - mesh.V).cwiseAbs().maxCoeff(), 1e-7);  // float storage
}

TEST(Dataset, WriterNeverOverwritesUnlessTold) {
  const fs::path dir = Scratch().Subdirectory("overwrite");
  std::ofstream(dir / "notes.txt") << "precious";
  const std::string message = ErrorOf([&] { DatasetWriter(dir.string(), SmallRig(), {}); });
  EXPECT_CONTAINS(message, dir.string());
  EXPECT_CONTAINS(message, "not empty");
  EXPECT_FALSE(fs::exists(dir / "cameras.json"));
  WriteSmallDataset(dir, 2);  // overwrite = true
  EXPECT_TRUE(fs::exists(dir / "notes.txt")) << "only dataset entries are replaced";
  EXPECT_EQ(Dataset(dir.string()).frame_count(), 2);
}

TEST(Dataset, HoldsABoundedWindowOfFrames) {
  const fs::path dir = Scratch().Subdirectory("window");
  WriteSmallDataset(dir, 4);
  DatasetOptions options;
  options.cache_frames = 1;  // 3 cameras → at most 3 cached entries
  const Dataset dataset(dir.string(), options);
  const cv::Mat first = dataset.Image(2, 0);
  fs::remove(dataset.ImagePath(2, 0));
  // Still cached: served from memory although the file is gone.
  EXPECT_EQ(cv::norm(dataset.Image(2, 0), first, cv::NORM_INF), 0.0);
  // Three more entries push it out of the window: now it must be read again and fails.
  dataset.Image(2, 1);
  dataset.Image(2, 2);
  dataset.Image(2, 3);
  EXPECT_CONTAINS(ErrorOf([&] { dataset.Image(2, 0); }), "images/top/000000.png");
}

TEST(Dataset, ConcurrentReadsAgree) {
  const fs::path dir = Scratch().Subdirectory("threads");
  WriteSmallDataset(dir, 4);
  const Dataset dataset(dir.string());
  std::vector<double> sums(8);
  std::vector<std::thread> threads;
  for (int i = 0; i < 8; ++i)
    threads.emplace_back([&, i] {
      double sum = 0;
      for (int repeat = 0; repeat < 20; ++repeat)
        for (int c = 0; c < 3; ++c)
          for (int f = 0; f < 4; ++f) sum += cv::sum(dataset.Gray(c, (f + i) % 4))[0];
      sums[i] = sum;
    });
  for (auto& thread : threads) thread.join();
  for (double sum : sums) EXPECT_EQ(sum, sums[0]);
}

TEST(Dataset, ReadsFramesFromVideos) {
  const fs::path dir = Scratch().Subdirectory("videos");
  const std::vector<Camera> cameras = {LookAt("a", {-1, -1, 0.3}, 32, 24, 30), LookAt("b", {1, -1, 0.3}, 32, 24, 30)};
  WriteCamerasJson((dir / "cameras.json").string(), cameras, 25.0, std::nullopt, std::nullopt);
  fs::create_directories(dir / "videos");
  for (const Camera& camera : cameras) {
    // FFV1 is lossless, so decoded frames equal the written ones.
    cv::VideoWriter writer((dir / "videos" / (camera.name() + ".avi")).string(),
                           cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 25, cv::Size(32, 24), true);
    ASSERT_TRUE(writer.isOpened());
    for (int f = 0; f < 6; ++f) writer.write(RandomImage(32, 24, CV_8UC3, 50 + f));
  }
  const Dataset dataset(dir.string());
  EXPECT_TRUE(dataset.has_videos());
  EXPECT_EQ(dataset.frame_count(), 6);
  for (int f : {0, 1, 4, 2, 5, 3})  // sequential and seeking reads
    EXPECT_EQ(cv::norm(dataset.Image(1, f), RandomImage(32, 24, CV_8UC3, 50 + f), cv::NORM_INF), 0.0) << f;
}

TEST(Dataset, SkipsForwardThroughAVideoWithoutTheCache) {
  const fs::path dir = Scratch().Subdirectory("videos_skip");
  const std::vector<Camera> cameras = {LookAt("a", {-1, -1, 0.3}, 32, 24, 30), LookAt("b", {1, -1, 0.3}, 32, 24, 30)};
  WriteCamerasJson((dir / "cameras.json").string(), cameras, 25.0, std::nullopt, std::nullopt);
  fs::create_directories(dir / "videos");
  for (const Camera& camera : cameras) {
    cv::VideoWriter writer((dir / "videos" / (camera.name() + ".avi")).string(),
                           cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 25, cv::Size(32, 24), true);
    ASSERT_TRUE(writer.isOpened());
    for (int f = 0; f < 9; ++f) writer.write(RandomImage(32, 24, CV_8UC3, 70 + f));
  }
  DatasetOptions options;
  options.cache_frames = 0;  // every read decodes
  const Dataset dataset(dir.string(), options);
  // A subsampled pass (skips forward), then a step back (seeks), then forward again.
  for (int f : {0, 3, 4, 8, 2, 7})
    EXPECT_EQ(cv::norm(dataset.Image(0, f), RandomImage(32, 24, CV_8UC3, 70 + f), cv::NORM_INF), 0.0) << f;
  // Two passes interleaved, one forwards from frame 4 and one backwards from frame 3 (the
  // motion chains side by side): each read still returns its own frame.
  for (int f : {4, 3, 5, 2, 6, 1, 7, 0, 8})
    EXPECT_EQ(cv::norm(dataset.Image(1, f), RandomImage(32, 24, CV_8UC3, 70 + f), cv::NORM_INF), 0.0) << f;
}

// --- Malformed inputs: one test each, asserting that the message names the file, the
// field and the expectation.

class MalformedDataset : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = Scratch().Subdirectory(::testing::UnitTest::GetInstance()->current_test_info()->name());
    WriteSmallDataset(dir_, 3);
  }
  std::string OpenError(bool check_headers = true) const {
    DatasetOptions options;
    options.check_image_headers = check_headers;
    return ErrorOf([&] { Dataset(dir_.string(), options); });
  }
  static DatasetOptions NoHeaderCheck() {
    DatasetOptions options;
    options.check_image_headers = false;
    return options;
  }
  fs::path Json() const { return dir_ / "cameras.json"; }
  fs::path dir_;
};

TEST_F(MalformedDataset, BadJson) {
  ReplaceInFile(Json(), "\"cameras\"", "\"cameras\" :: oops");
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, Json().string());
  EXPECT_CONTAINS(message, "line ");
  EXPECT_CONTAINS(message, "invalid JSON");
}

TEST_F(MalformedDataset, MissingField) {
  EditJson(Json(), [](nlohmann::json& root) { root["cameras"][0].erase("height"); });
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, Json().string());
  EXPECT_CONTAINS(message, "cameras[0] (\"left\").height");
  EXPECT_CONTAINS(message, "missing required field");
}

TEST_F(MalformedDataset, WrongFormatString) {
  EditJson(Json(), [](nlohmann::json& root) { root["format"] = "multiview-video/2"; });
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, Json().string());
  EXPECT_CONTAINS(message, "format");
  EXPECT_CONTAINS(message, "expected \"multiview-video/1\"");
}

TEST_F(MalformedDataset, NonRotationR) {
  EditJson(Json(), [](nlohmann::json& root) { root["cameras"][1]["R"][0][0] = 1.2 * root["cameras"][1]["R"][0][0].get<double>(); });
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, Json().string());
  EXPECT_CONTAINS(message, "camera \"right\": R");
  EXPECT_CONTAINS(message, "expected a rotation");
}

TEST_F(MalformedDataset, NegativeWidth) {
  EditJson(Json(), [](nlohmann::json& root) { root["cameras"][0]["width"] = -16; });
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, Json().string());
  EXPECT_CONTAINS(message, "cameras[0] (\"left\").width");
  EXPECT_CONTAINS(message, "expected an integer in [1, 32768]");
}

TEST_F(MalformedDataset, CameraWithNoImages) {
  for (const auto& entry : fs::directory_iterator(dir_ / "images" / "right")) fs::remove(entry.path());
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, (dir_ / "images" / "right").string());
  EXPECT_CONTAINS(message, "has no images");
  EXPECT_CONTAINS(message, "expected");
}

TEST_F(MalformedDataset, MissingFrame) {
  fs::remove(dir_ / "images" / "top" / "000001.png");
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, (dir_ / "images" / "top" / "000001.png").string());
  EXPECT_CONTAINS(message, "missing frame 1");
  EXPECT_CONTAINS(message, "every camera must have frames 0..2");
}

TEST_F(MalformedDataset, FramesOfDifferentSizes) {
  const fs::path path = dir_ / "images" / "left" / "000002.png";
  cv::imwrite(path.string(), RandomImage(17, 12, CV_8UC3, 3));
  for (bool check_headers : {true, false}) {
    std::string message = OpenError(check_headers);
    if (!check_headers) {
      EXPECT_EQ(message, "no error");
      const Dataset dataset(dir_.string(), NoHeaderCheck());
      message = ErrorOf([&] { dataset.Image(0, 2); });
    }
    EXPECT_CONTAINS(message, path.string());
    EXPECT_CONTAINS(message, "size");
    EXPECT_CONTAINS(message, "expected 16×12");
    EXPECT_CONTAINS(message, "got 17×12");
  }
}

TEST_F(MalformedDataset, UnreadableImage) {
  const fs::path path = dir_ / "masks" / "right" / "000001.png";
  std::ofstream(path, std::ios::trunc) << "this is not a PNG";
  EXPECT_CONTAINS(OpenError(), path.string());
  EXPECT_CONTAINS(OpenError(), "unreadable image: expected a PNG");
  const Dataset dataset(dir_.string(), NoHeaderCheck());
  const std::string message = ErrorOf([&] { dataset.Mask(1, 1); });
  EXPECT_CONTAINS(message, path.string());
  EXPECT_CONTAINS(message, "unreadable image");
}

TEST_F(MalformedDataset, UnknownCameraFolder) {
  fs::create_directories(dir_ / "images" / "cam99");
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, (dir_ / "images" / "cam99").string());
  EXPECT_CONTAINS(message, "unknown camera folder");
  EXPECT_CONTAINS(message, "left, right, top");
}

TEST_F(MalformedDataset, BoundsMinNotBelowMax) {
  EditJson(Json(), [](nlohmann::json& root) { root["bounds"]["max"][0] = root["bounds"]["min"][0]; });
  const std::string message = OpenError();
  EXPECT_CONTAINS(message, Json().string());
  EXPECT_CONTAINS(message, "bounds");
  EXPECT_CONTAINS(message, "expected min < max");
}

}  // namespace
}  // namespace subflow::vision
