// The photometric residual families of the stereo refinement
// (solver/stereo/photometric_residuals.h), each on its own, on exact synthetic images of a
// static scene (tests/solver/refinement_test_scene.h): stereo blocks measure agreement
// between cameras, temporal blocks between frames, silhouette blocks the outline.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "solver/stereo/photometric_residuals.h"
#include "tests/solver/refinement_test_scene.h"

namespace subflow::solver {
namespace {

using testing::OpenedWindow;
using testing::Scene;
using geometry::Positions;

ceres::Problem::Options NoLossOwnership() {
  ceres::Problem::Options options;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

// Mean NCC over the pairs of the stereo blocks at the window's current increments
// (NCC = 1 − ‖r_pair‖² / (2 W), exact for ε = 0).
double MeanStereoNcc(ceres::Problem& problem, const std::vector<ResidualRecord>& records) {
  double sum = 0.0;
  int count = 0;
  for (const ResidualRecord& record : records) {
    std::vector<double*> blocks;
    problem.GetParameterBlocksForResidualBlock(record.id, &blocks);
    Eigen::VectorXd r(record.correlation->pair_residual_count());
    record.correlation->PairResiduals(blocks.data(), r.data());
    int offset = 0;
    for (const CorrelationPair& pair : record.correlation->pairs()) {
      const int n = static_cast<int>(pair.rows.size());
      sum += 1.0 - r.segment(offset, n).squaredNorm() / (2.0 * pair.weight);
      ++count;
      offset += n;
    }
  }
  return sum / count;
}

TEST(CamerasOfPatch, RanksAtMostMaxCamerasByFacing) {
  StereoRefinementOptions options;
  options.ncc_epsilon = 0.0;
  OpenedWindow opened(Scene(), Scene().scene.control, 1, 0, 0, 0, options);
  int seen_by_two = 0;
  for (int f = 0; f < Scene().scene.hierarchy.FaceCount(0); ++f) {
    const PatchCameras seen = CamerasOfPatch(opened.window, 0, f);
    ASSERT_LE(seen.cameras.size(), 3u);
    ASSERT_EQ(seen.cameras.size(), seen.cosines.size());
    EXPECT_TRUE(std::is_sorted(seen.cosines.rbegin(), seen.cosines.rend())) << "face " << f;
    for (double cosine : seen.cosines) EXPECT_GT(cosine, 0.0);
    seen_by_two += seen.cameras.size() >= 2;
  }
  // The dome of cameras looks at the upper half of the object.
  EXPECT_GT(seen_by_two, Scene().scene.hierarchy.FaceCount(0) / 3);
}

// At the true shape the cameras agree (NCC near 1); 1.5 mm along the normals (about one
// pixel), they agree less. ε = 0 so that the NCC read off the residual is exact.
TEST(StereoResidual, CamerasAgreeAtTheTrueShapeAndLessOffIt) {
  StereoRefinementOptions options;
  options.ncc_epsilon = 0.0;
  OpenedWindow opened(Scene(), Scene().scene.control, 1, 0, 0, 0, options);
  RefinementWindow& window = opened.window;
  ceres::Problem problem(NoLossOwnership());
  std::vector<ResidualRecord> records;
  const int faces = Scene().scene.hierarchy.FaceCount(0);
  int stereo_patches = 0;  // patches with a pair of cameras
  for (int f = 0; f < faces; ++f) {
    const PatchCameras seen = CamerasOfPatch(window, 0, f);
    stereo_patches += seen.cameras.size() >= 2;
    if (auto record = AddStereoResidual(window, 0, f, seen, nullptr, &problem)) {
      EXPECT_LE(record->correlation->pairs().size(), 3u);  // pairs of the 3 best cameras
      EXPECT_EQ(record->frame, 0);
      std::vector<double*> blocks;
      problem.GetParameterBlocksForResidualBlock(record->id, &blocks);
      EXPECT_EQ(blocks.size(), window.sampling->support[f].size());  // the patch's support, frame 0
      records.push_back(*record);
    }
  }
  EXPECT_GE(records.size(), 0.9 * stereo_patches);  // a block unless no pair shares min_samples
  EXPECT_GT(stereo_patches, faces / 3);
  const double at_truth = MeanStereoNcc(problem, records);
  EXPECT_GT(at_truth, 0.95);  // measured 0.976
  for (auto& [frame, state] : window.states) std::fill(state.increments.begin(), state.increments.end(), 0.0015);
  const double off = MeanStereoNcc(problem, records);
  std::printf("mean NCC of %zu stereo blocks: %.4f at the truth, %.4f 1.5 mm off\n", records.size(), at_truth, off);
  EXPECT_LT(off, at_truth - 0.05) << at_truth << " -> " << off;
}

// The same images at every frame and the same surface: each temporal block compares a
// camera's view of the patch with itself, so its residual is exactly zero; the window's
// first frame (when not the sequence's) has a step back as well as forward.
TEST(TemporalResiduals, VanishOnAStaticSceneWithStepsForwardAndBackAtTheWindowStart) {
  OpenedWindow opened(Scene(), Scene().scene.control, 3, 0, 1, 1);
  RefinementWindow& window = opened.window;
  ceres::Problem problem(NoLossOwnership());
  int blocks = 0, patches = 0;
  const int faces = Scene().scene.hierarchy.FaceCount(0);
  for (int f = 0; f < faces; ++f) {
    const PatchCameras seen = CamerasOfPatch(window, 1, f);
    const int added = AddTemporalResiduals(window, 1, f, seen, nullptr, &problem);
    EXPECT_LE(added, 2);
    blocks += added;
    patches += !seen.cameras.empty();
  }
  EXPECT_EQ(blocks, 2 * patches);  // (1, 2) and (0, 1) for every patch seen at all
  double cost = -1.0;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  EXPECT_EQ(cost, 0.0);

  // Off: no block.
  StereoRefinementOptions off;
  off.temporal_weight = 0.0;
  OpenedWindow without(Scene(), Scene().scene.control, 3, 0, 1, 1, off);
  ceres::Problem empty(NoLossOwnership());
  for (int f = 0; f < faces; ++f)
    EXPECT_EQ(AddTemporalResiduals(without.window, 1, f, CamerasOfPatch(without.window, 1, f), nullptr, &empty), 0);
}

// The residuals (pixels × weight) of the silhouette blocks of a window of `shape` on level
// `level` with `options`; `tight`: whether the silhouettes are the object's own outlines;
// `covered`: as if the surface covered the whole image in every camera (something beyond
// every rim).
std::vector<double> OutlineResiduals(const std::vector<cv::Mat>& masks, int level = 0,
                                     StereoRefinementOptions options = {},
                                     const Positions& shape = Scene().scene.control, bool tight = true,
                                     bool covered = false) {
  OpenedWindow opened(Scene(), shape, 1, level, 0, 0, options, &masks);
  opened.sequence.tight_outline.assign(opened.sequence.cameras.size(), tight ? 1 : 0);
  if (covered)
    for (cv::Mat& coverage : opened.window.states.at(0).coverage) coverage.setTo(255);
  ceres::Problem problem(NoLossOwnership());
  std::vector<ResidualRecord> records;
  for (int f = 0; f < Scene().scene.hierarchy.FaceCount(level); ++f)
    AddSilhouetteResiduals(opened.window, 0, f, &problem, &records);
  std::vector<double> residuals;
  for (const ResidualRecord& record : records) {
    EXPECT_EQ(record.correlation, nullptr);
    double r = 0.0, cost = 0.0;
    problem.EvaluateResidualBlock(record.id, false, &cost, &r, nullptr);
    residuals.push_back(r);
  }
  return residuals;
}

// The one-sided outline blocks alone (no rim), their count and mean residual.
int SilhouetteBlocks(const std::vector<cv::Mat>& masks, double* mean_residual, int level = 0,
                     StereoRefinementOptions options = {}) {
  options.rim_band = 0.0;
  const std::vector<double> residuals = OutlineResiduals(masks, level, options);
  double sum = 0.0;
  for (double r : residuals) {
    EXPECT_GE(r, 0.0);  // one-sided
    sum += r;
  }
  *mean_residual = residuals.empty() ? 0.0 : sum / residuals.size();
  return static_cast<int>(residuals.size());
}

// Masks shrunk by 8 px around each camera's silhouette.
std::vector<cv::Mat> ShrunkMasks() {
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(17, 17));
  std::vector<cv::Mat> shrunk;
  for (const cv::Mat& mask : Scene().masks) {
    shrunk.emplace_back();
    cv::erode(mask, shrunk.back(), kernel);
  }
  return shrunk;
}

// The outline blocks start at silhouette_from_level (0 by default): with 1, none on the
// base level and blocks again on level 1.
TEST(SilhouetteResiduals, StartAtTheirCoarsestLevel) {
  const std::vector<cv::Mat> shrunk = ShrunkMasks();
  double mean = 0;
  StereoRefinementOptions from_level_1;
  from_level_1.silhouette_from_level = 1;
  EXPECT_EQ(StereoRefinementOptions().silhouette_from_level, 0);
  EXPECT_GT(SilhouetteBlocks(shrunk, &mean, 0, StereoRefinementOptions()), 0);
  EXPECT_EQ(SilhouetteBlocks(shrunk, &mean, 0, from_level_1), 0);
  EXPECT_GT(SilhouetteBlocks(shrunk, &mean, 1, from_level_1), 0);
}

// One-sided: masks grown by 8 px leave every patch inside (no block); the exact masks
// give blocks only along the outline, with residuals of a fraction of a pixel; masks
// shrunk by 8 px leave many patches outside, with residuals of pixels.
TEST(SilhouetteResiduals, OnlyWhereThePatchReachesTheOutline) {
  const double weight = StereoRefinementOptions().silhouette_weight;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(17, 17));
  std::vector<cv::Mat> grown, shrunk;
  for (const cv::Mat& mask : Scene().masks) {
    grown.emplace_back();
    shrunk.emplace_back();
    cv::dilate(mask, grown.back(), kernel);
    cv::erode(mask, shrunk.back(), kernel);
  }
  double mean_grown = 0, mean_exact = 0, mean_shrunk = 0;
  EXPECT_EQ(SilhouetteBlocks(grown, &mean_grown), 0);
  const int exact = SilhouetteBlocks(Scene().masks, &mean_exact);
  const int outside = SilhouetteBlocks(shrunk, &mean_shrunk);
  EXPECT_GT(outside, 2 * exact);
  EXPECT_LT(mean_exact, 1.0 * weight);   // < 1 px
  EXPECT_GT(mean_shrunk, 2.0 * weight);  // > 2 px
}

// The rim: a surface shrunk by about 1.5 px inside the exact masks is drawn back out
// (blocks with negative residuals, of about the shrinkage) only by the rim term; the
// one-sided term alone leaves it where it is, and so does the rim term where the
// silhouettes only bound the object (projected hulls), or where the surface covers the
// image beyond the rim. On the true surface the blocks pull both ways by a fraction of a
// pixel (picking the rim sample that projects outermost
// instead gave 11 inward and 336 outward blocks there, 0.32 px on average).
TEST(SilhouetteResiduals, RimIsDrawnOntoMaskOutlinesFromBothSides) {
  const double weight = StereoRefinementOptions().silhouette_weight;
  EXPECT_GT(StereoRefinementOptions().rim_band, 0.0);
  const Positions shrunk = testing::Shrunk(Scene(), 1.5);

  const auto negatives = [](const std::vector<double>& residuals, double* mean) {
    int count = 0;
    double sum = 0.0;
    for (double r : residuals)
      if (r < 0) ++count, sum += r;
    *mean = count ? sum / count : 0.0;
    return count;
  };
  double mean = 0.0;
  StereoRefinementOptions no_rim;
  no_rim.rim_band = 0.0;
  const std::vector<double> with_rim = OutlineResiduals(Scene().masks, 0, {}, shrunk);
  EXPECT_GT(negatives(with_rim, &mean), 20);
  EXPECT_LT(mean, -0.7 * weight);
  EXPECT_GT(mean, -2.5 * weight);
  EXPECT_EQ(negatives(OutlineResiduals(Scene().masks, 0, no_rim, shrunk), &mean), 0);
  EXPECT_EQ(negatives(OutlineResiduals(Scene().masks, 0, {}, shrunk, false), &mean), 0);
  // A rim with surface just beyond it in the image lies in front of another part, whose
  // outline the silhouette is: it is not drawn.
  EXPECT_EQ(negatives(OutlineResiduals(Scene().masks, 0, {}, shrunk, true, true), &mean), 0);

  const std::vector<double> on_truth = OutlineResiduals(Scene().masks, 1);
  int inside = 0, outside = 0;
  double sum = 0.0;
  for (double r : on_truth) {
    inside += r < 0;
    outside += r > 0;
    sum += std::abs(r);
  }
  EXPECT_GT(inside, 50);
  EXPECT_GT(outside, 50);
  EXPECT_LT(sum / on_truth.size(), 0.3 * weight);
}

}  // namespace
}  // namespace subflow::solver
