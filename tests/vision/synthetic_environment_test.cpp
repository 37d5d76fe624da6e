// What `subflow synth` puts around its subjects and how it films them: textured floor and
// room (the background image is the clean plate), soft shadows, distractors outside the
// working volume or in front of a camera, lens distortion, MP4 videos, the front rig.
#include "vision/synthetic_render.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "geometry/mesh_io.h"
#include "vision/camera_rig.h"
#include "vision/dataset.h"
#include "vision/mask_agreement.h"
#include "vision/zbuffer.h"
#include "tests/test_support.h"

namespace subflow::vision {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("synthetic_environment_test");
  return scratch;
}

// A small sphere scene (icosphere of 3 levels, r = 0.1): fast to render.
SynthOptions Small(int cameras = 3, int frames = 1) {
  SynthOptions options;
  options.scene.scene = "sphere";
  options.scene.subdivisions = 3;
  options.scene.frame_count = frames;
  options.rig.camera_count = cameras;
  options.rig.width = 160;
  options.rig.height = 120;
  options.render.supersample = 2;
  options.colour_cameras = {};
  return options;
}

// Pixels farther than 2 px from the mask, where `image` and `background` differ.
int DifferingPixelsAwayFromTheObject(const cv::Mat& image, const cv::Mat& background, const cv::Mat& mask,
                                     int threshold = 0) {
  cv::Mat near_object, difference;
  cv::dilate(mask, near_object, cv::Mat::ones(5, 5, CV_8U));
  cv::absdiff(image, background, difference);
  difference.setTo(0, near_object);
  return cv::countNonZero(difference.reshape(1) > threshold);
}

TEST(SynthEnvironment, RoomIsTexturedAndTheBackgroundImageIsItsCleanPlate) {
  SynthOptions options = Small();
  options.environment.kind = "room";
  const fs::path directory = Scratch().FreshPath("room");
  WriteSyntheticDataset(directory.string(), options);
  const Dataset dataset(directory.string());
  ASSERT_TRUE(dataset.has_background() && dataset.has_masks());
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const cv::Mat image = dataset.Image(c, 0), background = dataset.Background(c), mask = dataset.Mask(c, 0);
    // Without shadows, distractors or noise, the scene minus the subject is the plate.
    EXPECT_EQ(DifferingPixelsAwayFromTheObject(image, background, mask), 0) << "camera " << c;
    // Every background pixel sees the textured room (not a flat backdrop): strong contrast.
    cv::Scalar mean, deviation;
    cv::meanStdDev(background, mean, deviation);
    EXPECT_GT(deviation[0], 20.0) << "camera " << c;
    // The mask is the subject only: it matches the z-buffer of the ground truth.
    const geometry::TriangleMesh truth = geometry::ReadMesh(dataset.GroundTruthMeshPath(0));
    const MaskAgreement agreement = CompareMasks(ZBuffer(dataset.camera(c), truth.V, truth.F).Mask(), mask);
    EXPECT_GE(agreement.iou, 0.98) << "camera " << c;
  }
}

TEST(SynthEnvironment, SoftShadowsDarkenTheFloorAndOnlyWhenAsked) {
  SynthOptions options = Small(2);
  options.rig.elevation_deg = 40.0;  // looking down at the floor around the sphere
  options.environment.kind = "floor";
  for (const bool shadows : {false, true}) {
    options.environment.shadows = shadows;
    const fs::path directory = Scratch().FreshPath(shadows ? "shadows" : "no_shadows");
    WriteSyntheticDataset(directory.string(), options);
    const Dataset dataset(directory.string());
    int darkened = 0, penumbra = 0;
    for (int c = 0; c < dataset.camera_count(); ++c) {
      const cv::Mat image = dataset.Image(c, 0), plate = dataset.Background(c), mask = dataset.Mask(c, 0);
      cv::Mat near_object;
      cv::dilate(mask, near_object, cv::Mat::ones(5, 5, CV_8U));
      for (int y = 0; y < image.rows; ++y)
        for (int x = 0; x < image.cols; ++x) {
          if (near_object.at<std::uint8_t>(y, x)) continue;
          const double ratio = (image.at<std::uint8_t>(y, x) + 1.0) / (plate.at<std::uint8_t>(y, x) + 1.0);
          if (ratio < 0.9) ++darkened;
          if (ratio > 0.75 && ratio < 0.95) ++penumbra;
        }
    }
    if (shadows) {
      EXPECT_GT(darkened, 100);  // a shadow on the floor
      EXPECT_GT(penumbra, 20);   // with a soft edge
    } else {
      EXPECT_EQ(darkened, 0);
    }
  }
}

TEST(SynthEnvironment, DistractorsStayOutsideTheVolumeOrHideTheSubjectInCameraZeroOnly) {
  SynthOptions options = Small(3);
  options.environment.kind = "floor";
  options.environment.distractors = "both";
  options.scene.start_frame = 20;  // the crosser (period 60, phase 1) is in front of cam00
  const fs::path directory = Scratch().FreshPath("distractors");
  WriteSyntheticDataset(directory.string(), options);
  const Dataset dataset(directory.string());
  const geometry::TriangleMesh truth = geometry::ReadMesh(dataset.GroundTruthMeshPath(0));
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const MaskAgreement agreement =
        CompareMasks(ZBuffer(dataset.camera(c), truth.V, truth.F).Mask(), dataset.Mask(c, 0));
    if (c == 0) {
      EXPECT_LT(agreement.count_b, 0.8 * agreement.count_a);  // the ball hides part of the sphere
    } else {
      EXPECT_GE(agreement.iou, 0.98) << "camera " << c;
    }
  }
  // The walker never enters the working volume over a whole period of its path.
  const std::vector<Camera> cameras = dataset.cameras();
  const SyntheticEnvironment walker_only({"floor", "walker"}, truth.V.colwise().minCoeff(),
                                         truth.V.colwise().maxCoeff(), cameras, options.rig.distance);
  const Eigen::Index static_vertices = walker_only.static_geometry().V.rows();
  for (int f = 0; f < 150; f += 5) {
    const TexturedMesh mesh = walker_only.AtFrame(f);
    ASSERT_GT(mesh.V.rows(), static_vertices);
    for (Eigen::Index v = static_vertices; v < mesh.V.rows(); ++v)
      ASSERT_FALSE(dataset.bounds().Contains(mesh.V.row(v).transpose())) << "frame " << f;
  }
}

// With lens distortion, the mask is the sphere's silhouette through the DISTORTED camera
// model: pixel (x, y) is inside when the ray Camera::BackProject((x, y)) passes within r of
// the centre. k1 = −0.4 at f = 300 shrinks the 50 px disk's area by ≈ 2 %, so the check
// can tell the distorted silhouette from the pinhole one.
TEST(SynthEnvironment, DistortedMasksFollowTheDistortedCameraModel) {
  SynthOptions options = Small(2);
  options.scene.subdivisions = 5;  // the icosphere within 3e-5 m of the sphere
  options.render.supersample = 3;  // odd: "more than half of the samples" is unbiased
  options.rig.focal = 300.0;
  options.distortion = {-0.4, 0.0, 0.0, 0.0, 0.0};
  const fs::path directory = Scratch().FreshPath("distorted");
  WriteSyntheticDataset(directory.string(), options);
  const Dataset dataset(directory.string());
  const geometry::TriangleMesh truth = geometry::ReadMesh(dataset.GroundTruthMeshPath(0));
  const Eigen::Vector3d centre = truth.V.colwise().mean();
  for (int c = 0; c < dataset.camera_count(); ++c) {
    const Camera& camera = dataset.camera(c);
    ASSERT_TRUE(camera.HasDistortion());
    cv::Mat distorted = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1), pinhole = distorted.clone();
    const Eigen::Vector3d to_centre = centre - camera.Center();
    auto inside = [&](const Eigen::Vector3d& ray) {
      const double along = ray.normalized().dot(to_centre);
      return along > 0.0 && to_centre.squaredNorm() - along * along <= 0.01;
    };
    for (int y = 0; y < camera.height(); ++y)
      for (int x = 0; x < camera.width(); ++x) {
        if (inside(camera.BackProject({x, y}))) distorted.at<std::uint8_t>(y, x) = 255;
        if (inside(camera.BackProjectUndistorted({x, y}))) pinhole.at<std::uint8_t>(y, x) = 255;
      }
    const MaskAgreement with_model = CompareMasks(dataset.Mask(c, 0), distorted);
    const MaskAgreement with_pinhole = CompareMasks(dataset.Mask(c, 0), pinhole);
    std::printf("%s: mask %lld, distorted model %lld, pinhole %lld, IoU %.4f / %.4f\n", camera.name().c_str(), with_model.count_a, with_model.count_b, with_pinhole.count_b, with_model.iou, with_pinhole.iou);
    EXPECT_GE(with_model.iou, 0.99) << camera.name();
    EXPECT_LT(std::abs(with_model.count_a - with_model.count_b), 0.005 * with_model.count_b) << camera.name();
    EXPECT_GT(std::abs(with_pinhole.count_a - with_pinhole.count_b), 0.012 * with_pinhole.count_b) << camera.name();
  }
}

TEST(SynthEnvironment, VideosDecodeToTheRenderedFrames) {
  SynthOptions options = Small(2, 3);
  options.scene.motion = 5.0;
  const fs::path png = Scratch().FreshPath("png"), mp4 = Scratch().FreshPath("mp4");
  WriteSyntheticDataset(png.string(), options);
  options.video = "mp4";
  try {
    WriteSyntheticDataset(mp4.string(), options);
  } catch (const Error& error) {
    if (std::string(error.what()).find("cannot write MP4") != std::string::npos)
      GTEST_SKIP() << "this OpenCV has no MP4 writer: " << error.what();
    throw;
  }
  EXPECT_FALSE(fs::exists(mp4 / "images"));
  const Dataset frames(png.string()), video(mp4.string());
  ASSERT_TRUE(video.has_videos());
  ASSERT_EQ(video.frame_count(), 3);
  for (int c = 0; c < 2; ++c)
    for (int f = 0; f < 3; ++f) {
      cv::Mat difference;
      cv::absdiff(frames.Gray(c, f), video.Gray(c, f), difference);
      EXPECT_LT(cv::mean(difference)[0], 0.03) << "camera " << c << " frame " << f;  // lossy, but close
    }
}

TEST(SynthEnvironment, FrontRigSeesOnlyTheFrontHalf) {
  CameraRigOptions rig;
  rig.rig = "front";
  rig.camera_count = 11;
  const std::vector<Camera> cameras = MakeCameraRig(rig);
  ASSERT_EQ(cameras.size(), 11u);
  for (const Camera& camera : cameras) {
    EXPECT_LT(camera.Center().y(), -0.25 * rig.distance) << camera.name();  // in front (−y)
    EXPECT_GT(camera.ViewDirection().y(), 0.2) << camera.name();            // looking at the subject
  }
}

TEST(SynthEnvironment, RejectsNonsenseOptions) {
  SynthOptions options = Small();
  options.environment.kind = "garden";
  EXPECT_THROW(options.Check(), Error);
  options = Small();
  options.distortion = {0.1, 0.2};
  EXPECT_THROW(options.Check(), Error);
  options = Small();
  options.video = "avi";
  EXPECT_THROW(options.Check(), Error);
}

}  // namespace
}  // namespace subflow::vision
