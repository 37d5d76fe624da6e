// Still sets without masks or background (vision/still_evidence.h, plane_sweep.h,
// depth_fusion.h): a textured sphere on a textured floor in a textured room, one frame,
// seen by a ring of 12 cameras (30° apart) at 128×96 — the object has its surroundings'
// texture, so only geometry separates them.
#include "vision/still_evidence.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/test_support.h"
#include "vision/dataset.h"
#include "vision/synthetic_render.h"
#include "vision/voxel_carving.h"
#include "vision/voxel_projection.h"

namespace subflow::vision {
namespace {

// The still scene, written once for the whole file (its masks are the ground truth the
// evidence is compared with; the evidence never reads them).
class StillScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new test::TemporaryDirectory("still_evidence_test");
    SynthOptions options;
    options.scene.scene = "sphere";
    options.scene.frame_count = 1;
    options.scene.subdivisions = 3;
    options.rig.rig = "ring";
    options.rig.camera_count = 12;
    options.rig.width = 128;
    options.rig.height = 96;
    options.render.supersample = 2;
    options.environment.kind = "room";
    options.write_background = false;
    options.colour_cameras = {};
    WriteSyntheticDataset(scratch_->string() + "/still", options);
    dataset_ = new Dataset(scratch_->string() + "/still");
    maps_ = new std::vector<DepthMap>(SweepDepthMaps(dataset_->cameras(), GrayImages(), dataset_->bounds()));
  }
  static void TearDownTestSuite() {
    delete maps_;
    delete dataset_;
    delete scratch_;
  }
  // Steps 2–5 of the still evidence on the file's depth maps.
  static StillEvidence Evidence(const StillEvidenceOptions& options = {}) {
    return StillEvidenceFromDepthMaps(dataset_->cameras(), GrayImages(), *maps_, dataset_->bounds(),
                                      ChooseResolution(dataset_->cameras(), dataset_->bounds(), {}), options);
  }

  static std::vector<cv::Mat> GrayImages() {
    std::vector<cv::Mat> gray;
    for (int k = 0; k < dataset_->camera_count(); ++k) gray.push_back(dataset_->Gray(k, 0));
    return gray;
  }
  // Mean IoU of the still silhouettes with the true masks.
  static double MeanIoU(const StillEvidence& evidence) {
    double sum = 0;
    for (int k = 0; k < dataset_->camera_count(); ++k) sum += SilhouetteIoU(evidence.silhouettes[k], dataset_->Mask(k, 0));
    return sum / dataset_->camera_count();
  }

  static test::TemporaryDirectory* scratch_;
  static Dataset* dataset_;
  static std::vector<DepthMap>* maps_;
};
test::TemporaryDirectory* StillScene::scratch_ = nullptr;
Dataset* StillScene::dataset_ = nullptr;
std::vector<DepthMap>* StillScene::maps_ = nullptr;

TEST_F(StillScene, TrustedDepthsLieOnTheTrueSurface) {
  // Where a camera's trusted depth falls on the sphere (its mask), the point is on the
  // true sphere to within two depth steps of the sweep.
  const std::vector<DepthMap>& maps = *maps_;
  const std::vector<cv::Mat> trusted = TrustedDepths(dataset_->cameras(), maps);
  const Eigen::Vector3d centre = dataset_->bounds().Center();
  // The sphere scene's radius: the bounds are its box grown by 10 % per side.
  const double radius = 0.5 * dataset_->bounds().Size().x() / 1.2;
  int checked = 0, within = 0;
  for (int k = 0; k < dataset_->camera_count(); ++k) {
    const cv::Mat mask = dataset_->Mask(k, 0);
    for (int v = 0; v < mask.rows; ++v)
      for (int u = 0; u < mask.cols; ++u) {
        const float q = trusted[k].at<float>(v, u);
        if (q <= 0 || !mask.at<uchar>(v, u)) continue;
        const Eigen::Vector3d X = PointAtDepth(dataset_->camera(k), Eigen::Vector2d(u, v), 1.0 / q);
        const double step = maps[k].inverse_depth_step / (q * q);  // depth step (world units) there
        ++checked;
        within += std::abs((X - centre).norm() - radius) <= 2 * step;
      }
  }
  ASSERT_GT(checked, 2000);
  EXPECT_GT(static_cast<double>(within) / checked, 0.9) << within << " of " << checked;
}

TEST_F(StillScene, SilhouettesOfAnObjectWithItsRoomsTextureMatchItsMasks) {
  const StillEvidence evidence = Evidence();
  ASSERT_TRUE(evidence.support.found) << evidence.support.Describe();
  // The floor (z = lowest point of the sphere − 2 mm), seen from above.
  EXPECT_GT(evidence.support.normal.z(), 0.99) << evidence.support.Describe();
  EXPECT_NEAR(-evidence.support.offset / evidence.support.normal.z(), -0.102, evidence.support.tolerance);
  // Measured 0.877 (the masks' own hull, 34 voxels across the volume, reaches ~0.9).
  EXPECT_GT(MeanIoU(evidence), 0.85);
}

TEST_F(StillScene, WithoutTheSupportPlaneTheFloorJoinsTheObject) {
  // The floor inside the volume is as photo-consistent as the sphere: without finding and
  // removing it, the silhouettes take in the floor under the object.
  StillEvidenceOptions options;
  options.remove_support_plane = false;
  const StillEvidence evidence = Evidence(options);
  EXPECT_FALSE(evidence.support.found);
  EXPECT_LT(MeanIoU(evidence), 0.7);
}

TEST(StillEvidenceOptions, BadValuesAreErrorsNamingTheField) {
  StillEvidenceOptions options;
  options.sweep.window_radius = 0;
  try {
    options.Check();
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("window_radius"), std::string::npos) << error.what();
  }
  options = {};
  options.fusion.free_votes = 0;
  EXPECT_THROW(options.Check(), Error);
  options = {};
  options.support_tolerance_planes = 0;
  EXPECT_THROW(options.Check(), Error);
}

TEST(PlaneSweep, ImagesOfTheWrongSizeOrTypeAreErrors) {
  Eigen::Matrix3d K;
  K << 20, 0, 7.5, 0, 20, 5.5, 0, 0, 1;
  const Camera a("a", 16, 12, K, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1));
  const Camera b("b", 16, 12, K, Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.1, 0, 1));
  const Bounds bounds{Eigen::Vector3d(-0.1, -0.1, -0.1), Eigen::Vector3d(0.1, 0.1, 0.1)};
  const cv::Mat good(12, 16, CV_32F, cv::Scalar(0.5)), small(10, 16, CV_32F), bytes(12, 16, CV_8U);
  EXPECT_THROW(SweepDepthMaps({a, b}, {good, small}, bounds), Error);
  EXPECT_THROW(SweepDepthMaps({a, b}, {good, bytes}, bounds), Error);
  EXPECT_THROW(SweepDepthMaps({a}, {good}, bounds), Error);
  EXPECT_NO_THROW(SweepDepthMaps({a, b}, {good, good}, bounds));
}

}  // namespace
}  // namespace subflow::vision
