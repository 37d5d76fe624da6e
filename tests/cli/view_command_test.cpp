// `subflow view` writes one HTML page that headless Chromium (Debian `chromium`) opens
// without network: the page reports itself ready with no error logged, the surface covers
// a plausible share of the picture, and two frames differ where the object moved. The
// page's open time and frame time are printed (measured, not asserted: see the report).
// Skipped, saying so, where Chromium is not installed.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/output/tiny_result.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;
using test::RunSubflow;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("view_command");
  return scratch;
}
std::string Quote(const fs::path& path) { return "'" + path.string() + "'"; }

constexpr int kWidth = 800, kHeight = 600;

// A tiny result that moves 1.5 cm per frame (the sphere's radius is 10 cm) and its page.
const fs::path& Page() {
  static const fs::path page = [] {
    test::TinyResultOptions options;
    options.translation = Eigen::RowVector3d(0.015, 0.0, 0.0);
    test::WriteTinyResult(Scratch() / "result", options);
    const fs::path path = Scratch() / "viewer.html";
    const test::CommandResult run =
        RunSubflow("view " + Quote(Scratch() / "result") + " --out " + Quote(path), Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return path;
  }();
  return page;
}

// Runs headless Chromium on the page with `query` and `mode` (--screenshot=... or
// --dump-dom), a fresh profile each time; returns stdout.
std::string Chromium(const std::string& query, const std::string& mode, const std::string& name) {
  const fs::path profile = Scratch().FreshPath("profile_" + name), out = Scratch() / (name + ".out");
  const std::string command =
      "cd " + Quote(Scratch().path()) + " && timeout 120 chromium --headless --no-sandbox --disable-gpu "
      "--disable-background-networking --disable-component-update --disable-sync --no-first-run "
      "--user-data-dir=" + Quote(profile) + " --window-size=" + std::to_string(kWidth) + "," + std::to_string(kHeight) +
      " --virtual-time-budget=10000 " + mode + " 'file://" + Page().string() + query + "' > " + Quote(out) + " 2> " +
      Quote(Scratch() / (name + ".err"));
  EXPECT_EQ(std::system(command.c_str()), 0) << test::ReadTextFile(Scratch() / (name + ".err"));
  return test::ReadTextFile(out);
}

// The page's view without its panels (title top left, scale top right, controls at the
// bottom): pixels unlike the background #f4f4f4 are surface.
cv::Mat SurfaceMask(const cv::Mat& screenshot) {
  const cv::Mat view = screenshot(cv::Rect(0, 50, kWidth - 220, kHeight - 110));
  cv::Mat background;
  cv::inRange(view, cv::Scalar(234, 234, 234), cv::Scalar(254, 254, 254), background);
  return 255 - background;
}

bool ChromiumAvailable() { return std::system("chromium --version > /dev/null 2>&1") == 0; }

TEST(ViewCommand, PageOpensWithoutErrorsAndReportsItsTimes) {
  if (!ChromiumAvailable()) GTEST_SKIP() << "Chromium is not installed (Debian package chromium; scripts/install_deps.sh)";
  const std::string dom = Chromium("?frame=2&benchmark=20", "--dump-dom", "dom");
  const std::string marker = "<pre id=\"subflow-status\">";
  const std::size_t at = dom.find(marker);
  ASSERT_NE(at, std::string::npos) << dom.substr(0, 2000);
  const std::string text = dom.substr(at + marker.size(), dom.find("</pre>", at) - at - marker.size());
  ASSERT_FALSE(text.empty()) << "the page's script did not run";
  const nlohmann::json status = nlohmann::json::parse(text);
  EXPECT_TRUE(status["ready"].get<bool>());
  EXPECT_TRUE(status["errors"].empty()) << status.dump();
  EXPECT_EQ(status["frame"], 2);
  std::cout << "viewer: open " << status["open_ms"] << " ms, frame " << status["frame_ms"] << " ms (update "
            << status["update_ms"] << " ms), renderer " << status["renderer"] << "\n";
  // Chromium's own log names page errors "CONSOLE(...)" at level ERROR.
  const std::string log = test::ReadTextFile(Scratch() / "dom.err");
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
}

TEST(ViewCommand, SurfaceCoversThePictureAndMovesBetweenFrames) {
  if (!ChromiumAvailable()) GTEST_SKIP() << "Chromium is not installed (Debian package chromium; scripts/install_deps.sh)";
  Chromium("?frame=0", "--screenshot=" + Quote(Scratch() / "frame0.png"), "frame0");
  Chromium("?frame=4", "--screenshot=" + Quote(Scratch() / "frame4.png"), "frame4");
  const cv::Mat first = cv::imread((Scratch() / "frame0.png").string()), last = cv::imread((Scratch() / "frame4.png").string());
  ASSERT_FALSE(first.empty());
  ASSERT_EQ(first.size(), cv::Size(kWidth, kHeight));
  ASSERT_EQ(last.size(), first.size());
  const cv::Mat a = SurfaceMask(first), b = SurfaceMask(last);
  const double pixels = a.total();
  // The camera frames the whole sequence's bounding sphere: the object fills part of the view.
  for (const cv::Mat* mask : {&a, &b}) {
    EXPECT_GT(cv::countNonZero(*mask) / pixels, 0.03);
    EXPECT_LT(cv::countNonZero(*mask) / pixels, 0.6);
  }
  // The object moved 6 cm (0.3 of its size): its picture moved, and the pictures differ
  // only where the object is in one frame or the other.
  cv::Mat difference, changed;
  cv::absdiff(first(cv::Rect(0, 50, kWidth - 220, kHeight - 110)), last(cv::Rect(0, 50, kWidth - 220, kHeight - 110)), difference);
  cv::cvtColor(difference, difference, cv::COLOR_BGR2GRAY);
  cv::threshold(difference, changed, 12, 255, cv::THRESH_BINARY);
  EXPECT_GT(cv::countNonZero(a ^ b), 0.01 * pixels);
  cv::Mat near_object;
  cv::dilate(a | b, near_object, cv::Mat(), cv::Point(-1, -1), 2);
  EXPECT_GE(cv::countNonZero(changed & near_object), 0.99 * cv::countNonZero(changed));
  const cv::Moments ma = cv::moments(a, true), mb = cv::moments(b, true);
  const double shift = std::hypot(ma.m10 / ma.m00 - mb.m10 / mb.m00, ma.m01 / ma.m00 - mb.m01 / mb.m00);
  EXPECT_GT(shift, 10.0) << "the surface's centroid moved " << shift << " px";
}

// Every second frame of the 5: frames 0, 2, 4 in the page, played at half the rate so
// that time stays real, and the report says so.
TEST(ViewCommand, StrideKeepsEveryKthFrame) {
  test::TinyResultOptions options;
  test::WriteTinyResult(Scratch() / "strided_result", options);
  const fs::path page = Scratch() / "strided.html";
  const test::CommandResult run =
      RunSubflow("view " + Quote(Scratch() / "strided_result") + " --stride 2 --out " + Quote(page), Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const nlohmann::json report = nlohmann::json::parse(test::ReadTextFile(page.string() + ".report.json"));
  EXPECT_EQ(report["stride"], 2);
  EXPECT_EQ(report["frames_in_page"], 3);
  const std::string html = test::ReadTextFile(page);
  EXPECT_NE(html.find("\"frame_names\":[\"000000\",\"000002\",\"000004\"]"), std::string::npos)
      << html.substr(0, 400);
  EXPECT_NE(html.find("\"fps\":12.5"), std::string::npos);
}

TEST(ViewCommand, RefusesAnAbsurdSizeCap) {
  const test::CommandResult run = RunSubflow("view " + Quote(Scratch() / "result") + " --max-megabytes 0 --out " +
                                                 Quote(Scratch() / "never.html"), Scratch().path());
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("--max-megabytes"), std::string::npos) << run.output();
  EXPECT_FALSE(fs::exists(Scratch() / "never.html"));
}

TEST(ViewCommand, RefusesToOverwrite) {
  const fs::path page = Page();
  const test::CommandResult again = RunSubflow("view " + Quote(Scratch() / "result") + " --out " + Quote(page), Scratch().path());
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.err.find("exists"), std::string::npos) << again.output();
}

}  // namespace
}  // namespace subflow
