// What stands (almost) still in a take (vision/standing_evidence.h): a swaying textured
// disk beside a walking one, in front of a static textured background with sensor noise.
// The background estimated from the video keeps the swaying disk, so the difference to it
// misses the disk; the spread of the free samples finds it.
#include "vision/standing_evidence.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "vision/voxel_projection.h"

namespace subflow::vision {
namespace {

constexpr int kWidth = 120, kHeight = 90, kFrames = 24;
const cv::Point2d kStandingCentre(38, 45);
constexpr double kStandingRadius = 16, kWalkerRadius = 11;

// A smooth random texture in [low, high] (value noise blurred), fixed by `seed`.
cv::Mat Texture(unsigned seed, int width, int height, double low = 0.4, double high = 0.9) {
  cv::Mat texture(height, width, CV_32F);
  cv::RNG random(seed);
  random.fill(texture, cv::RNG::UNIFORM, low, high);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);
  return texture;
}

// Pastes the disk of `texture` (centred in it) with its centre at `centre` (sub-pixel, by
// a translation with bilinear interpolation); `mask` receives the disk's pixels.
void PasteDisk(const cv::Mat& texture, double radius, const cv::Point2d& centre, cv::Mat* image, cv::Mat* mask) {
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, centre.x - texture.cols / 2.0, 0, 1,
                         centre.y - texture.rows / 2.0);
  cv::Mat moved, disk = cv::Mat::zeros(texture.size(), CV_32F), moved_disk;
  cv::circle(disk, cv::Point(texture.cols / 2, texture.rows / 2), static_cast<int>(radius), cv::Scalar(1), -1);
  cv::warpAffine(texture, moved, shift, image->size(), cv::INTER_LINEAR);
  cv::warpAffine(disk, moved_disk, shift, image->size(), cv::INTER_LINEAR);
  *image = image->mul(1 - moved_disk) + moved.mul(moved_disk);
  if (mask) *mask = moved_disk > 0.5;
}

struct Take {
  std::vector<cv::Mat> frames;  // gray CV_32F
  cv::Mat standing_mask;        // the swaying disk at its rest position
  std::vector<cv::Mat> walker_masks;
};

// The walker crosses the right half of the image; the standing disk drifts slowly, by up
// to ±2 px over the take (a person's sway seen from a few metres: a few centimetres in a
// second or two, too slow for the motion evidence of any one frame).
Take MakeTake() {
  Take take;
  // The standing disk is darker than the background (dark clothes before a light wall).
  const cv::Mat background = Texture(1, kWidth, kHeight), standing = Texture(2, 40, 40, 0.05, 0.45),
                walker = Texture(3, 30, 30, 0.05, 0.45);
  std::mt19937 random(4);
  std::normal_distribution<float> noise(0.0f, 1.0f / 255);
  take.standing_mask = cv::Mat::zeros(kHeight, kWidth, CV_8U);
  cv::Mat rest = background.clone();
  PasteDisk(standing, kStandingRadius, kStandingCentre, &rest, &take.standing_mask);
  for (int f = 0; f < kFrames; ++f) {
    cv::Mat image = background.clone(), walker_mask;
    const cv::Point2d sway(2.0 * std::sin(2 * M_PI * f / 48), 1.5 * std::sin(2 * M_PI * f / 64 + 1));
    PasteDisk(standing, kStandingRadius, kStandingCentre + sway, &image, nullptr);
    PasteDisk(walker, kWalkerRadius, cv::Point2d(66 + 40.0 * f / (kFrames - 1), 40 + 6 * std::sin(0.5 * f)), &image,
              &walker_mask);
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) image.at<float>(y, x) += noise(random);
    take.frames.push_back(image);
    take.walker_masks.push_back(walker_mask);
  }
  return take;
}

double Coverage(const cv::Mat& silhouette, const cv::Mat& region) {
  return static_cast<double>(cv::countNonZero(silhouette & region)) / cv::countNonZero(region);
}

TEST(StandingEvidence, FindsWhatSwaysWhereTheEstimatedBackgroundKeepsIt) {
  const Take take = MakeTake();
  const SilhouetteOptions options;
  const EstimatedBackground background = EstimateBackground(take.frames, take.frames, options);
  ASSERT_TRUE(background.valid());
  ASSERT_FALSE(background.instability.empty());
  // The difference to the estimated background misses the swaying disk (the median keeps it)...
  const Silhouette difference = SilhouetteFromEstimatedBackground(take.frames[kFrames / 2], background, options);
  EXPECT_LT(Coverage(difference.mask, take.standing_mask), 0.3);
  // ...the standing silhouette covers it, and little else.
  const Silhouette standing = StandingSilhouette(background, options);
  ASSERT_FALSE(standing.empty) << "threshold " << standing.threshold;
  const double iou = SilhouetteIoU(standing.mask, take.standing_mask);
  EXPECT_GT(iou, 0.8) << iou;
  RecordProperty("standing_iou", std::to_string(iou));
  std::printf("standing silhouette IoU %.3f, difference coverage %.3f\n", iou, Coverage(difference.mask, take.standing_mask));
  // The walker, free where it was, is not standing anywhere it passed.
  for (int f = 0; f < kFrames; f += 6) EXPECT_LT(Coverage(standing.mask, take.walker_masks[f]), 0.1) << "frame " << f;
}

TEST(StandingEvidence, AStaticSceneHasNoStandingSilhouette) {
  // Only sensor noise changes: nothing is above the noise factor × its own median.
  Take take = MakeTake();
  const cv::Mat background = Texture(1, kWidth, kHeight);
  std::mt19937 random(9);
  std::normal_distribution<float> noise(0.0f, 1.0f / 255);
  for (int f = 0; f < kFrames; ++f) {
    cv::Mat image = background.clone(), walker_mask;
    PasteDisk(Texture(3, 30, 30), kWalkerRadius, cv::Point2d(20 + 80.0 * f / (kFrames - 1), 45), &image, nullptr);
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) image.at<float>(y, x) += noise(random);
    take.frames[f] = image;
  }
  const EstimatedBackground estimate = EstimateBackground(take.frames, take.frames, {});
  ASSERT_TRUE(estimate.valid());
  const Silhouette standing = StandingSilhouette(estimate, {});
  EXPECT_LT(standing.object_pixels, kWidth * kHeight / 100) << standing.object_pixels << " pixels";
}

TEST(StandingEvidence, IsAddedToEachCamerasSilhouette) {
  const cv::Mat a = cv::Mat::zeros(10, 10, CV_8U), b = cv::Mat::zeros(10, 10, CV_8U);
  a(cv::Rect(0, 0, 4, 4)) = 255;
  b(cv::Rect(6, 6, 3, 3)) = 255;
  std::vector<Silhouette> silhouettes{SilhouetteFromMask(a), SilhouetteFromMask(cv::Mat::zeros(10, 10, CV_8U))};
  silhouettes[0].source = silhouettes[1].source = EvidenceSource::kBackground;
  const std::vector<Silhouette> standing{SilhouetteFromMask(b), Silhouette{}};
  AddStandingEvidence(standing, &silhouettes);
  EXPECT_EQ(silhouettes[0].object_pixels, 16 + 9);
  EXPECT_EQ(cv::countNonZero(silhouettes[0].evidence > 0.5), 16 + 9);
  EXPECT_EQ(silhouettes[0].source, EvidenceSource::kBackground);
  EXPECT_TRUE(silhouettes[1].empty);  // an empty standing silhouette adds nothing
}

TEST(StandingEvidence, BadOptionsAreErrors) {
  StandingEvidenceOptions options;
  options.noise_factor = 0.5;
  EXPECT_THROW(options.Check(), Error);
  options = {};
  options.min_threshold = -1;
  EXPECT_THROW(options.Check(), Error);
}

}  // namespace
}  // namespace subflow::vision
