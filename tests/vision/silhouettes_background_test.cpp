// Claims of vision/silhouettes_background.h: a soft shadow (and a sharp, thin one) cast on
// a textured floor is background, while the object standing in it stays object; the
// threshold of each camera follows that camera's noise, measured where the scene is surely
// background; the surely-background pixels are those outside the projected working volume.
#include "vision/silhouettes_background.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vision/camera.h"
#include "vision/voxel_projection.h"
#include "vision/working_volume.h"

namespace subflow::vision {
namespace {

// A floor-like texture: Voronoi cells of random colour (seed spacing `cell` px), dark
// 1-px joints, slightly blurred (anti-aliasing); CV_32FC(channels) in [0, 1], sRGB-encoded.
cv::Mat CellTexture(int width, int height, int cell, int channels, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> position(0, 1), level(0.25f, 0.85f);
  std::vector<cv::Point2f> seeds;
  std::vector<cv::Vec3f> colours;
  for (int i = 0; i < width * height / (cell * cell); ++i) {
    seeds.emplace_back(position(random) * width, position(random) * height);
    colours.emplace_back(level(random), level(random), level(random));
  }
  cv::Mat texture(height, width, CV_32FC3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float best = 1e30f, second = 1e30f;
      int nearest = 0;
      for (size_t i = 0; i < seeds.size(); ++i) {
        const float d = std::hypot(seeds[i].x - x, seeds[i].y - y);
        if (d < best) second = best, best = d, nearest = static_cast<int>(i);
        else if (d < second) second = d;
      }
      texture.at<cv::Vec3f>(y, x) = second - best < 1.0f ? colours[nearest] * 0.5f : colours[nearest];
    }
  cv::GaussianBlur(texture, texture, cv::Size(), 0.6);
  if (channels == 1) cv::cvtColor(texture, texture, cv::COLOR_BGR2GRAY);
  return texture;
}

float Encode(float linear) {
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1 / 2.4f) - 0.055f;
}

// `encoded` darkened by the gain field (on decoded values), re-encoded.
cv::Mat Shade(const cv::Mat& encoded, const cv::Mat& gain) {
  cv::Mat linear = DecodeSrgb(encoded), shaded = encoded.clone();
  const int channels = encoded.channels();
  for (int y = 0; y < encoded.rows; ++y)
    for (int x = 0; x < encoded.cols * channels; ++x)
      shaded.ptr<float>(y)[x] = Encode(gain.at<float>(y, x / channels) * linear.ptr<float>(y)[x]);
  return shaded;
}

cv::Mat To8Bit(const cv::Mat& unit, double noise_sigma = 0, unsigned seed = 0) {
  cv::Mat noisy = unit.clone();
  if (noise_sigma > 0) {
    cv::Mat noise(unit.size(), unit.type());
    cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    noisy += noise;
  }
  cv::Mat result;
  noisy.convertTo(result, CV_MAKETYPE(CV_8U, unit.channels()), 255.0);
  return result;
}

double IoU(const cv::Mat& a, const cv::Mat& b) {
  return static_cast<double>(cv::countNonZero(a & b)) / std::max(1, cv::countNonZero(a | b));
}

// A floor of 12-px cells; the object (a disk with its own finer cells) stands at the right
// of its soft shadow (an ellipse, gain 0.35 inside, a 6-px penumbra, touching the object)
// and a sharp, 2-px-wide shadow strip (a thin leg's) runs off to the left. Gray (the hard
// case: no colour to tell a darker object from a shadow) and colour.
class ShadowOnTexturedFloor : public ::testing::TestWithParam<int> {};

TEST_P(ShadowOnTexturedFloor, IsBackgroundWhileTheObjectInItStaysObject) {
  const int channels = GetParam(), width = 200, height = 150;
  const cv::Mat floor = CellTexture(width, height, 12, channels, 3);
  const cv::Mat skin = CellTexture(width, height, 6, channels, 4);
  cv::Mat object = cv::Mat::zeros(height, width, CV_8UC1);
  cv::circle(object, cv::Point(130, 70), 28, cv::Scalar(255), cv::FILLED);
  cv::Mat shadow = cv::Mat::zeros(height, width, CV_32F);
  cv::ellipse(shadow, cv::Point(95, 95), cv::Size(50, 22), 0, 0, 360, cv::Scalar(1), cv::FILLED);
  cv::GaussianBlur(shadow, shadow, cv::Size(), 2.0);  // penumbra ≈ 6 px
  cv::line(shadow, cv::Point(10, 125), cv::Point(70, 112), cv::Scalar(1), 2);  // sharp thin strip
  const cv::Mat gain = 1.0 - 0.65 * shadow;
  cv::Mat scene = Shade(floor, gain);
  skin.copyTo(scene, object);
  const cv::Mat image = To8Bit(scene), background = To8Bit(floor);
  // The shadow's pixels away from the object (the closing may bridge 2 px at its edge).
  cv::Mat near_object;
  cv::dilate(object, near_object, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
  const cv::Mat shadowed = (shadow > 0.1f) & ~near_object;

  SilhouetteOptions plain;
  plain.background_shadow_test = false;
  const Silhouette without = SilhouetteFromBackground(image, background, plain);
  const Silhouette with = SilhouetteFromBackground(image, background);
  const double shadow_pixels = cv::countNonZero(shadowed);
  const double in_shadow_without = cv::countNonZero(without.mask & shadowed) / shadow_pixels;
  const double in_shadow_with = cv::countNonZero(with.mask & shadowed) / shadow_pixels;
  std::printf("[ figures ] %d channel(s): shadow taken for object %.3f → %.3f; IoU with the object %.3f → %.3f\n",
              channels, in_shadow_without, in_shadow_with, IoU(without.mask, object), IoU(with.mask, object));
  EXPECT_GT(in_shadow_without, 0.5);  // the plain difference sees the shadow as object
  EXPECT_LT(in_shadow_with, 0.02);
  // The object keeps its outline: the blur and the closing cost about a pixel of the rim
  // (2π·28 / (π·28²) ≈ 7 % of its area at most).
  EXPECT_GT(IoU(with.mask, object), 0.93);
  EXPECT_LT(IoU(without.mask, object), 0.8);
}

INSTANTIATE_TEST_SUITE_P(GrayAndColour, ShadowOnTexturedFloor, ::testing::Values(1, 3));

// A uniform darkening of the whole frame (an exposure change) is no object either.
TEST(ShadowRobustDifference, ExplainsAGlobalGainButNotAnObjectOfAnotherTexture) {
  const cv::Mat floor = CellTexture(120, 90, 10, 3, 5), other = CellTexture(120, 90, 10, 3, 6);
  const cv::Mat darker = Shade(floor, cv::Mat(90, 120, CV_32F, cv::Scalar(0.6)));
  const double tolerance = 0.02;
  const cv::Mat explained = ShadowRobustDifference(To8Bit(darker), To8Bit(floor), tolerance);
  const cv::Mat replaced = ShadowRobustDifference(To8Bit(other), To8Bit(floor), tolerance);
  EXPECT_LT(cv::mean(explained)[0], 0.01);
  EXPECT_LT(cv::countNonZero(explained > tolerance), 0.01 * explained.total());
  EXPECT_GT(cv::countNonZero(replaced > tolerance), 0.9 * replaced.total());
  // Without the test, m is the plain difference d.
  SilhouetteOptions plain;
  plain.background_shadow_test = false;
  const cv::Mat d = ShadowRobustDifference(To8Bit(darker), To8Bit(floor), tolerance, plain);
  EXPECT_EQ(cv::norm(d, BackgroundDifference(To8Bit(darker), To8Bit(floor)), cv::NORM_INF), 0.0);
}

// Two cameras see the same scene, one with little noise and one with a lot. The object
// fills 60 % of the frame, so the histogram's dominant peak can be the object's (it is for
// the quiet camera, whose background peak is a single bin) and the histogram threshold
// then misreads it; the noise of the border, which is surely background, gives each
// camera its own threshold.
TEST(NoiseThreshold, FollowsEachCamerasNoise) {
  const int width = 160, height = 120;
  const cv::Mat floor = CellTexture(width, height, 12, 1, 7);
  cv::Mat object = cv::Mat::zeros(height, width, CV_8UC1);
  cv::ellipse(object, cv::Point(80, 60), cv::Size(66, 50), 0, 0, 360, cv::Scalar(255), cv::FILLED);
  cv::Mat scene = floor.clone();
  cv::Mat(floor + 0.22).copyTo(scene, object);  // brighter than the floor everywhere
  cv::Mat border = cv::Mat(height, width, CV_8UC1, cv::Scalar(255));
  border(cv::Rect(12, 8, width - 24, height - 16)).setTo(0);

  SilhouetteOptions histogram;
  histogram.min_background_fraction = 1.0;  // never enough surely-background pixels
  double thresholds[2] = {0, 0};
  const double sigmas[2] = {0.5 / 255, 0.03};
  for (int camera = 0; camera < 2; ++camera) {
    const cv::Mat image = To8Bit(scene, sigmas[camera], 10 + camera);
    const cv::Mat background = To8Bit(floor, sigmas[camera], 20 + camera);
    const Silhouette adaptive = SilhouetteFromBackground(image, background, {}, border);
    const Silhouette fixed = SilhouetteFromBackground(image, background, histogram, border);
    thresholds[camera] = adaptive.threshold;
    const double false_positive = cv::countNonZero(adaptive.mask & ~object) / double(cv::countNonZero(~object));
    std::printf("[ figures ] noise σ %.4f: threshold %.4f (histogram %.4f), IoU %.3f (histogram %.3f), "
                "false positives %.4f\n",
                sigmas[camera], adaptive.threshold, fixed.threshold, IoU(adaptive.mask, object),
                IoU(fixed.mask, object), false_positive);
    EXPECT_GT(IoU(adaptive.mask, object), 0.97);
    EXPECT_LT(false_positive, 0.005);
    if (camera == 0) {
      EXPECT_LT(IoU(fixed.mask, object), 0.9);  // the histogram threshold fails here
    }
  }
  EXPECT_GT(thresholds[1], 3 * thresholds[0]);  // the noisy camera's threshold is its own

  // The estimate itself: median + factor · 1.4826 · MAD over the border; invalid with too
  // few border pixels.
  cv::Mat noise(height, width, CV_32F);
  cv::RNG(3).fill(noise, cv::RNG::NORMAL, 0.0, 0.01);
  noise = cv::abs(noise);
  const NoiseThreshold estimate = EstimateNoiseThreshold(noise, border);
  EXPECT_TRUE(estimate.valid);
  EXPECT_NEAR(estimate.median, 0.00674, 0.001);  // median of |N(0, 0.01)| = 0.6745 σ
  EXPECT_NEAR(estimate.threshold, estimate.median + 6 * estimate.sigma, 1e-9);
  cv::Mat corner = cv::Mat::zeros(height, width, CV_8UC1);
  corner(cv::Rect(0, 0, 5, 5)).setTo(255);
  EXPECT_FALSE(EstimateNoiseThreshold(noise, corner).valid);
  EXPECT_FALSE(EstimateNoiseThreshold(noise, cv::Mat()).valid);
}

TEST(OutsideWorkingVolume, IsThePixelsFartherThanTheMarginFromTheBoxsProjection) {
  Eigen::Matrix3d K;
  K << 200, 0, 79.5, 0, 200, 59.5, 0, 0, 1;
  const Camera camera("cam", 160, 120, K, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1));
  const Bounds box{Eigen::Vector3d(-0.1, -0.05, -0.1), Eigen::Vector3d(0.1, 0.05, 0.1)};
  const cv::Mat outside = OutsideWorkingVolume(camera, box, 3.0);
  // The box's near face spans x ∈ 79.5 ± 200·0.1/0.9 = 79.5 ± 22.2 px (to 101.7), y ∈ 59.5 ± 11.1 px.
  EXPECT_EQ(outside.at<uint8_t>(60, 80), 0);
  EXPECT_EQ(outside.at<uint8_t>(60, 101), 0);   // inside the outline
  EXPECT_EQ(outside.at<uint8_t>(60, 104), 0);   // 2.3 px out: within the 3-px margin
  EXPECT_EQ(outside.at<uint8_t>(60, 106), 255);  // 4.3 px out: beyond it
  EXPECT_EQ(outside.at<uint8_t>(0, 0), 255);
  // Every projected corner lies in the not-outside part.
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d X(corner & 1 ? box.max.x() : box.min.x(), corner & 2 ? box.max.y() : box.min.y(),
                            corner & 4 ? box.max.z() : box.min.z());
    const Eigen::Vector2d pixel = camera.Project(X);
    EXPECT_EQ(outside.at<uint8_t>(static_cast<int>(std::lround(pixel.y())), static_cast<int>(std::lround(pixel.x()))), 0);
  }
  // A camera inside the box: nothing is surely background.
  const Camera inside("cam", 160, 120, K, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  EXPECT_EQ(cv::countNonZero(OutsideWorkingVolume(inside, box, 3.0)), 0);
}

}  // namespace
}  // namespace subflow::vision
