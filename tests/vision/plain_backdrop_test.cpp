// The plain backdrop of a still set (vision/plain_backdrop.h): its colour and spread read
// robustly on the border band, plain only where the backdrop has no texture.
#include "vision/plain_backdrop.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace subflow::vision {
namespace {

constexpr int kWidth = 160, kHeight = 120;

// A dark backdrop (BGR 12, 10, 8) with sensor noise (σ = 2 levels), a bright object in the
// middle, and a second bright region reaching into the top border band (96 of the 3-px
// band's 1,644 pixels).
cv::Mat DarkBackdropWithObjects() {
  cv::Mat image(kHeight, kWidth, CV_8UC3, cv::Scalar(12, 10, 8));
  cv::Mat noise(kHeight, kWidth, CV_16SC3);
  cv::randn(noise, 0, 2);
  cv::Mat wide;
  image.convertTo(wide, CV_16SC3);
  wide += noise;
  wide.convertTo(image, CV_8UC3);  // saturates at 0
  cv::ellipse(image, {80, 60}, {30, 20}, 0, 0, 360, cv::Scalar(200, 190, 180), cv::FILLED);
  cv::rectangle(image, cv::Rect(20, 0, 32, 15), cv::Scalar(220, 220, 220), cv::FILLED);
  return image;
}

// The border band of width `band`, drawn independently of BorderBand.
cv::Mat Band(int band) {
  cv::Mat sure(kHeight, kWidth, CV_8UC1, cv::Scalar(255));
  sure(cv::Rect(band, band, kWidth - 2 * band, kHeight - 2 * band)).setTo(0);
  return sure;
}

TEST(PlainBackdrop, DarkBackdropIsPlainWithItsColourDespiteAnObjectInTheBand) {
  const PlainBackdrop backdrop = MeasureBackdrop(DarkBackdropWithObjects(), Band(3));
  EXPECT_TRUE(backdrop.plain);
  EXPECT_EQ(backdrop.channels, 3);
  EXPECT_NEAR(backdrop.colour[0], 12 / 255.0, 1.5 / 255);
  EXPECT_NEAR(backdrop.colour[1], 10 / 255.0, 1.5 / 255);
  EXPECT_NEAR(backdrop.colour[2], 8 / 255.0, 1.5 / 255);
  EXPECT_LT(backdrop.spread, 0.03);
  EXPECT_EQ(backdrop.sure_pixels, kWidth * kHeight - (kWidth - 6) * (kHeight - 6));
  // The backdrop as a background image: its colour everywhere, in [0, 1].
  const cv::Mat image = BackdropImage(DarkBackdropWithObjects(), backdrop);
  ASSERT_EQ(image.type(), CV_32FC3);
  EXPECT_NEAR(image.at<cv::Vec3f>(60, 80)[0], backdrop.colour[0], 1e-6);
}

TEST(PlainBackdrop, AnObjectOnAThirdOfTheBandLeavesTheBackdropPlain) {
  // A textured object over the whole top edge and down the sides: 552 of the 1,644 band
  // pixels (34 %, under the 40 % the 60th percentile tolerates).
  cv::Mat image = DarkBackdropWithObjects();
  cv::randu(image(cv::Rect(0, 0, kWidth, 15)), 60, 250);
  const PlainBackdrop backdrop = MeasureBackdrop(image, Band(3));
  EXPECT_TRUE(backdrop.plain) << backdrop.spread;
  EXPECT_NEAR(backdrop.colour[0], 12 / 255.0, 2.5 / 255);
}

TEST(PlainBackdrop, GraySixteenBitAndAlphaImagesAreReadInUnitsOfTheirRange) {
  cv::Mat gray(kHeight, kWidth, CV_16UC1, cv::Scalar(0.2 * 65535));
  cv::circle(gray, {80, 60}, 30, cv::Scalar(60000), cv::FILLED);
  const PlainBackdrop from_gray = MeasureBackdrop(gray, Band(3));
  EXPECT_TRUE(from_gray.plain);
  EXPECT_EQ(from_gray.channels, 1);
  EXPECT_NEAR(from_gray.colour[0], 0.2, 1e-4);
  EXPECT_EQ(BackdropImage(gray, from_gray).type(), CV_32FC1);
  cv::Mat bgra(kHeight, kWidth, CV_8UC4, cv::Scalar(40, 50, 60, 255));
  const PlainBackdrop from_bgra = MeasureBackdrop(bgra, Band(3));
  EXPECT_TRUE(from_bgra.plain);
  EXPECT_EQ(from_bgra.channels, 3);  // alpha dropped
  EXPECT_NEAR(from_bgra.colour[2], 60 / 255.0, 1e-6);
  EXPECT_EQ(BackdropImage(bgra, from_bgra).type(), CV_32FC3);
}

TEST(PlainBackdrop, TexturedBackdropIsNotPlain) {
  // A room's texture: cells of random gray levels, 8 px wide.
  cv::Mat cells(kHeight / 8 + 1, kWidth / 8 + 1, CV_8UC1);
  cv::randu(cells, 0, 255);
  cv::Mat texture;
  cv::resize(cells, texture, cv::Size(), 8, 8, cv::INTER_NEAREST);
  const PlainBackdrop backdrop = MeasureBackdrop(texture(cv::Rect(0, 0, kWidth, kHeight)), Band(3));
  EXPECT_FALSE(backdrop.plain);
  EXPECT_GT(backdrop.spread, 0.1);
}

TEST(PlainBackdrop, ObjectCoveringMostOfTheBandIsNotTakenForTheBackdrop) {
  // An object that fills the frame leaves too little of the backdrop in the band to read.
  cv::Mat image = DarkBackdropWithObjects();
  cv::rectangle(image, cv::Rect(0, 0, kWidth, 80), cv::Scalar(150, 140, 130), cv::FILLED);
  cv::randu(image(cv::Rect(0, 0, kWidth, 80)), 60, 250);
  EXPECT_FALSE(MeasureBackdrop(image, Band(3)).plain);
}

TEST(PlainBackdrop, BorderBandIsTwoPercentOfTheShorterSideAndAtLeastTwoPixels) {
  // 2 % of 120 = 2.4 → 2 px.
  const cv::Mat band = BorderBand(cv::Size(kWidth, kHeight));
  EXPECT_EQ(cv::countNonZero(band != Band(2)), 0);
  PlainBackdropOptions wide;
  wide.border_fraction = 0.1;  // 12 px
  EXPECT_EQ(cv::countNonZero(BorderBand(cv::Size(kWidth, kHeight), wide) != Band(12)), 0);
  // A tiny image is all band.
  EXPECT_EQ(cv::countNonZero(BorderBand(cv::Size(3, 3))), 9);
}

TEST(PlainBackdropBadInput, OptionsOutOfRangeAndMasksOfAnotherSizeAreErrors) {
  PlainBackdropOptions options;
  options.max_spread = -0.1;
  EXPECT_THROW(options.Check(), Error);
  options = {};
  options.border_fraction = 0.5;
  EXPECT_THROW(options.Check(), Error);
  EXPECT_THROW(MeasureBackdrop(DarkBackdropWithObjects(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(255))), Error);
  // No surely-background pixel: nothing to read, so not plain.
  EXPECT_FALSE(MeasureBackdrop(DarkBackdropWithObjects(), cv::Mat::zeros(kHeight, kWidth, CV_8UC1)).plain);
}

}  // namespace
}  // namespace subflow::vision
