// `subflow synth`: its datasets must satisfy the same checks as the Blender-rendered blob
// (masks = our cameras + z-buffer on the ground truth), have fixed-connectivity ground
// truth with the advertised motion, and never clobber a directory.
#include "vision/synthetic_render.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "geometry/mesh_io.h"
#include "vision/dataset.h"
#include "vision/mask_agreement.h"
#include "vision/zbuffer.h"
#include "tests/test_support.h"

namespace subflow::vision {
namespace {

namespace fs = std::filesystem;

// This run's scratch directory (removed at exit); each test works below it.
const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("synth_test");
  return scratch;
}

SynthOptions SmallOptions(const std::string& scene, const std::string& rig) {
  SynthOptions options;
  options.scene.scene = scene;
  options.scene.frame_count = 3;
  options.scene.motion = 3.0;  // larger steps: 3 frames still span some motion
  options.rig.rig = rig;
  options.rig.camera_count = 4;
  options.rig.width = 160;
  options.rig.height = 120;
  options.colour_cameras = {0};
  return options;
}

// The blob check of zbuffer_test on a synth dataset: per camera IoU ≥ 0.99 and a mean
// centroid offset < 0.15 px between the written masks (3×3 supersampled coverage > 0.5)
// and our z-buffer at pixel centres on the written ground truth (float PLY).
void ExpectMasksMatchZBuffer(const fs::path& directory) {
  const Dataset dataset(directory.string());
  ASSERT_TRUE(dataset.has_masks());
  ASSERT_TRUE(dataset.has_groundtruth());
  for (int c = 0; c < dataset.camera_count(); ++c) {
    double min_iou = 1.0;
    Eigen::Vector2d offset = Eigen::Vector2d::Zero();
    for (int f = 0; f < dataset.frame_count(); ++f) {
      const geometry::TriangleMesh mesh = geometry::ReadMesh(dataset.GroundTruthMeshPath(f));
      const ZBuffer zbuffer(dataset.camera(c), mesh.V, mesh.F);
      const MaskAgreement agreement = CompareMasks(zbuffer.Mask(), dataset.Mask(c, f));
      EXPECT_GT(agreement.count_b, 500) << "the object must be in view";
      min_iou = std::min(min_iou, agreement.iou);
      offset += agreement.centroid_offset / dataset.frame_count();
    }
    std::printf("%s %s: min IoU %.4f, mean centroid offset (%+.4f, %+.4f) px\n",
                directory.filename().c_str(), dataset.camera(c).name().c_str(), min_iou, offset.x(),
                offset.y());
    EXPECT_GE(min_iou, 0.99) << dataset.camera(c).name();
    EXPECT_LT(offset.norm(), 0.15) << dataset.camera(c).name();
  }
}

TEST(Synth, BlobRingDatasetMasksMatchTheZBufferOfItsGroundTruth) {
  const fs::path directory = Scratch().FreshPath("blob");
  const SynthSummary summary = WriteSyntheticDataset(directory.string(), SmallOptions("blob", "ring"));
  EXPECT_EQ(summary.camera_count, 4);
  EXPECT_EQ(summary.frame_count, 3);
  EXPECT_EQ(summary.vertex_count, 10242);
  EXPECT_EQ(summary.face_count, 20480);
  ExpectMasksMatchZBuffer(directory);

  // Layout: colour camera 0 (BGR), gray others; backgrounds; bounds contain the object.
  const Dataset dataset(directory.string());
  EXPECT_EQ(dataset.Image(0, 0).channels(), 3);
  EXPECT_EQ(dataset.Image(1, 0).channels(), 1);
  ASSERT_TRUE(dataset.has_background());
  ASSERT_TRUE(dataset.bounds_from_file());
  for (int f = 0; f < dataset.frame_count(); ++f) {
    const geometry::TriangleMesh mesh = geometry::ReadMesh(dataset.GroundTruthMeshPath(f));
    for (Eigen::Index i = 0; i < mesh.V.rows(); i += 97)
      EXPECT_TRUE(dataset.bounds().Contains(mesh.V.row(i).transpose()));
  }
  // Without noise, pixels away from the object (mask dilated by 2 px) equal the
  // background image exactly; on the object the texture has contrast.
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const cv::Mat image = dataset.Image(c, 1), background = dataset.Background(c), mask = dataset.Mask(c, 1);
    cv::Mat near_object;
    cv::dilate(mask, near_object, cv::Mat::ones(5, 5, CV_8U));
    cv::Mat difference;
    cv::absdiff(image, background, difference);
    difference.setTo(0, near_object);
    EXPECT_EQ(cv::countNonZero(difference.reshape(1)), 0) << "camera " << c;
    cv::Scalar mean, deviation;
    cv::meanStdDev(dataset.Gray(c, 1), mean, deviation, mask);
    EXPECT_GT(deviation[0], 0.05) << "texture contrast on camera " << c;
  }
  fs::remove_all(directory);
}

TEST(Synth, RigidDomeAndHeadPartialDomeDatasetsPassTheMaskCheck) {
  const fs::path rigid = Scratch().FreshPath("rigid");
  WriteSyntheticDataset(rigid.string(), SmallOptions("rigid", "dome"));
  ExpectMasksMatchZBuffer(rigid);
  fs::remove_all(rigid);
  const fs::path head = Scratch().FreshPath("head");
  WriteSyntheticDataset(head.string(), SmallOptions("head", "partial-dome"));
  ExpectMasksMatchZBuffer(head);
  fs::remove_all(head);
}

// The same check made independent of the z-buffer: the `sphere` scene's written masks
// against the ANALYTIC silhouette of the sphere — the pixels (x, y) whose ray, with the
// DATASET.md convention (pixel (0, 0) = centre of the top-left pixel, ray direction
// Rᵀ K⁻¹ (x, y, 1) from the centre −Rᵀ t, K R t as written in cameras.json), passes within
// r of the sphere's centre. The masks are 3×3-supersampled coverage > ½, the analytic
// silhouette samples pixel centres: they may differ only on outline pixels, in both
// directions (a few % of the ~200 outline pixels of a 35 px radius disk), which keeps
// IoU ≥ 0.99 and the centroid offset near 0; a half-pixel convention error would shift
// the centroid by 0.5 px. The inscribed icosphere (5 levels) is within 3e-5 m (0.01 px)
// of the sphere. Same thresholds as the Blender blob: IoU ≥ 0.99, offset < 0.15 px.
void ExpectMasksMatchAnalyticSphere(const fs::path& directory) {
  const Dataset dataset(directory.string());
  ASSERT_TRUE(dataset.has_masks());
  std::ifstream json_file(directory / "cameras.json");
  const nlohmann::json json = nlohmann::json::parse(json_file);
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const nlohmann::json& entry = json.at("cameras").at(c);
    ASSERT_EQ(entry.at("name").get<std::string>(), dataset.camera(c).name());
    Eigen::Matrix3d K, R;
    Eigen::Vector3d t;
    for (int r = 0; r < 3; ++r) {
      t(r) = entry.at("t").at(r).get<double>();
      for (int k = 0; k < 3; ++k) {
        K(r, k) = entry.at("K").at(r).at(k).get<double>();
        R(r, k) = entry.at("R").at(r).at(k).get<double>();
      }
    }
    const Eigen::Vector3d centre_of_projection = -R.transpose() * t;
    const Eigen::Matrix3d ray_matrix = R.transpose() * K.inverse();  // pixel (x, y, 1) → ray
    // Our Camera's back-projection agrees with the file's convention (so what carving and
    // the z-buffer use is what this check checks).
    const Camera& camera = dataset.camera(c);
    EXPECT_LT((camera.Center() - centre_of_projection).norm(), 1e-12);
    for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(0, 0), Eigen::Vector2d(camera.width() - 1, 17.0)})
      EXPECT_LT((camera.BackProjectUndistorted(pixel).normalized() -
                 (ray_matrix * pixel.homogeneous()).normalized()).norm(), 1e-12);

    double min_iou = 1.0;
    Eigen::Vector2d offset = Eigen::Vector2d::Zero();
    for (int f = 0; f < dataset.frame_count(); ++f) {
      const geometry::TriangleMesh mesh = geometry::ReadMesh(dataset.GroundTruthMeshPath(f));
      const Eigen::Vector3d centre = mesh.V.colwise().mean();  // the icosphere is symmetric
      const double radius = (mesh.V.rowwise() - centre.transpose()).rowwise().norm().mean();
      ASSERT_NEAR(radius, 0.1, 1e-6);
      const Eigen::Vector3d to_centre = centre - centre_of_projection;
      cv::Mat analytic = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
      for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
          const Eigen::Vector3d ray = (ray_matrix * Eigen::Vector3d(x, y, 1.0)).normalized();
          const double along = ray.dot(to_centre);
          if (along > 0.0 && to_centre.squaredNorm() - along * along <= radius * radius)
            analytic.at<std::uint8_t>(y, x) = 255;
        }
      const MaskAgreement agreement = CompareMasks(dataset.Mask(c, f), analytic);
      EXPECT_GT(agreement.count_b, 500) << "the sphere must be in view";
      min_iou = std::min(min_iou, agreement.iou);
      offset += agreement.centroid_offset / dataset.frame_count();
    }
    std::printf("%s %s: min IoU %.4f against the analytic sphere, mean centroid offset (%+.4f, %+.4f) px\n",
                directory.filename().c_str(), camera.name().c_str(), min_iou, offset.x(), offset.y());
    EXPECT_GE(min_iou, 0.99) << camera.name();
    EXPECT_LT(offset.norm(), 0.15) << camera.name();
  }
}

TEST(Synth, SphereMasksMatchTheAnalyticSilhouetteOnRingAndPartialDome) {
  for (const std::string rig : {"ring", "partial-dome"}) {
    SynthOptions options = SmallOptions("sphere", rig);
    options.rig.camera_count = rig == "ring" ? 4 : 6;  // partial dome: two narrow cameras (2 and 5)
    options.scene.frame_count = 2;
    const fs::path directory = Scratch().FreshPath("sphere_" + rig);
    WriteSyntheticDataset(directory.string(), options);
    ExpectMasksMatchAnalyticSphere(directory);
    fs::remove_all(directory);
  }
}

TEST(Synth, RefusesANonEmptyDirectoryUnlessOverwriting) {
  const fs::path directory = Scratch().FreshPath("refuse");
  fs::create_directories(directory);
  std::ofstream(directory / "notes.txt") << "keep me\n";
  SynthOptions options = SmallOptions("blob", "ring");
  options.rig.camera_count = 2;
  options.scene.frame_count = 1;
  options.scene.subdivisions = 3;
  try {
    WriteSyntheticDataset(directory.string(), options);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("refusing to overwrite"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(directory / "cameras.json"));
  options.overwrite = true;
  WriteSyntheticDataset(directory.string(), options);
  EXPECT_TRUE(fs::exists(directory / "cameras.json"));
  EXPECT_TRUE(fs::exists(directory / "notes.txt"));  // only dataset entries are replaced
  fs::remove_all(directory);
}

TEST(Synth, ScenesKeepConnectivityAndMoveAsAdvertised) {
  for (const std::string& name : SyntheticSceneNames()) {
    SyntheticSceneOptions options;
    options.scene = name;
    options.frame_count = 4;
    options.subdivisions = 4;
    options.voxel_size = 0.0025;  // SDF subjects: coarse meshes are enough for the motion
    const SyntheticScene scene = MakeSyntheticScene(options);
    ASSERT_EQ(scene.frame_count(), 4);
    for (const auto& V : scene.frames) ASSERT_EQ(V.rows(), scene.rest.rows());
    const double mean_motion = (scene.frames[1] - scene.frames[0]).rowwise().norm().mean();
    EXPECT_GT(mean_motion, 2e-4) << name;  // every scene moves (~1 mm per frame)
    EXPECT_LT(mean_motion, 5e-3) << name;
  }
  // rigid: all pairwise distances are preserved (checked on a subset), to rounding.
  SyntheticSceneOptions rigid;
  rigid.scene = "rigid";
  rigid.frame_count = 5;
  rigid.subdivisions = 3;
  const SyntheticScene scene = MakeSyntheticScene(rigid);
  for (Eigen::Index i = 0; i < scene.rest.rows(); i += 7)
    for (Eigen::Index j = i + 1; j < scene.rest.rows(); j += 11)
      EXPECT_NEAR((scene.frames[4].row(i) - scene.frames[4].row(j)).norm(),
                  (scene.frames[0].row(i) - scene.frames[0].row(j)).norm(), 1e-12);
  // head: the back of the head turns rigidly (yaw about +z), the jaw moves more.
  SyntheticSceneOptions head;
  head.scene = "head";
  head.frame_count = 11;
  head.subdivisions = 4;
  const SyntheticScene h = MakeSyntheticScene(head);
  const Eigen::Matrix3d yaw = Eigen::AngleAxisd(12.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  double jaw_motion = 0.0;
  for (Eigen::Index i = 0; i < h.rest.rows(); ++i) {
    const Eigen::Vector3d rest = h.rest.row(i);
    const Eigen::Vector3d moved = h.frames[10].row(i);
    if (rest.y() > 0.0 || rest.z() > 0.0) EXPECT_LT((moved - yaw * rest).norm(), 1e-12) << "vertex " << i;
    if (rest.y() < -0.05 && rest.z() < -0.04) jaw_motion = std::max(jaw_motion, (moved - yaw * rest).norm());
  }
  EXPECT_GT(jaw_motion, 0.01);  // the chin drops by over a centimetre in 10 frames
}

TEST(Synth, SensorNoiseIsUnbiasedWithTheRequestedDeviation) {
  // The dark background has linear radiance 0.03 (synthetic_render.h), i.e. the sRGB
  // level L = 255 · (1.055 · 0.03^(1/2.4) − 0.055) ≈ 48.39 grey levels. The noiseless
  // image stores round(L) = 48; the noisy one round(L + N(0, σ²)), whose mean is L (to
  // 0.01, the dither effect of rounding with σ = 4 ≫ 1) — so noisy − clean has mean
  // L − round(L) ≈ +0.39, not 0 (the noise is unbiased with respect to the radiance,
  // not to the rounded clean image). Standard deviation √(σ² + 1/12) ≈ 4.01.
  // Tolerances: 19200 samples → standard error 4/√19200 ≈ 0.03 on the mean; ±0.1 and
  // ±0.2 on the deviation are over 3 standard errors.
  const Camera camera = LookAtCamera("cam", 160, 120, 210.0, Eigen::Vector3d(0.0, -0.6, 0.1), Eigen::Vector3d::Zero());
  SyntheticRenderOptions clean_options;
  SyntheticRenderOptions noisy_options;
  noisy_options.noise_sigma = 4.0;
  const cv::Mat clean = SyntheticRenderer(clean_options).RenderBackground(camera, false, 7);
  const cv::Mat noisy = SyntheticRenderer(noisy_options).RenderBackground(camera, false, 7);
  const double level = 255.0 * (1.055 * std::pow(0.03, 1.0 / 2.4) - 0.055);
  EXPECT_EQ(cv::countNonZero(clean != static_cast<int>(std::lround(level))), 0);
  cv::Scalar mean, deviation;
  cv::meanStdDev(noisy, mean, deviation);
  EXPECT_NEAR(mean[0], level, 0.1);
  EXPECT_NEAR(deviation[0], std::sqrt(16.0 + 1.0 / 12.0), 0.2);
  cv::Mat difference;
  cv::subtract(noisy, clean, difference, cv::noArray(), CV_64F);
  cv::meanStdDev(difference, mean, deviation);
  EXPECT_NEAR(mean[0], level - std::lround(level), 0.1);
}

TEST(Synth, CommandLineWritesADatasetAndRefusesToOverwrite) {
  const fs::path directory = Scratch().FreshPath("cli");
  const std::string arguments = "synth rigid --out '" + directory.string() +
                                "' --cameras 3 --frames 2 --width 64 --height 48 --subdivisions 3";
  test::CommandResult run = test::RunSubflow(arguments, Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  EXPECT_TRUE(fs::exists(directory / "images" / "cam02" / "000001.png"));
  EXPECT_TRUE(fs::exists(directory / "groundtruth" / "mesh" / "000001.ply"));
  run = test::RunSubflow(arguments, Scratch().path());
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output().find("refusing to overwrite"), std::string::npos) << run.output();
  run = test::RunSubflow(arguments + " --overwrite", Scratch().path());
  EXPECT_EQ(run.exit_code, 0) << run.output();
  run = test::RunSubflow("synth cube --out '" + directory.string() + "'", Scratch().path());
  EXPECT_NE(run.exit_code, 0) << run.output();
  fs::remove_all(directory);
}

}  // namespace
}  // namespace subflow::vision
