// Inputs the fuzz harnesses (fuzz/) found to break a reader, each now an error naming the
// file and the field (the inputs are also seeds in fuzz/corpus/).
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "vision/import_panoptic.h"
#include "vision/import_projection_matrices.h"

namespace subflow::vision {
namespace {

std::string ErrorOf(const std::string& text) {
  try {
    ParsePanopticCalibration(text, "calibration.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

// calibration_fuzzer, crash-panoptic-number-overflow: "-1e4444" escaped as nlohmann's
// out_of_range.406 and terminated the program.
TEST(FuzzRegressions, PanopticNumberBeyondDoubleRangeIsAnErrorNamingTheField) {
  EXPECT_EQ(ErrorOf("-1e4444\nt0r").rfind("calibration.json: (top level): number overflow", 0), 0u)
      << ErrorOf("-1e4444\nt0r");
  const std::string nested = ErrorOf(R"({"cameras": [{"name": "00_00", "K": [[1e999, 0, 0]]}]})");
  EXPECT_EQ(nested.rfind("calibration.json: cameras[0].K[0][0]: number overflow", 0), 0u) << nested;
  EXPECT_NE(nested.find("expected a finite number"), std::string::npos) << nested;
}

// projection_matrix_fuzzer, crash-0e96bcd9: a Middlebury file naming an image longer
// than a file name may be (255 bytes) made std::filesystem throw filesystem_error
// ("File name too long") out of the image-size lookup: it terminated the program.
TEST(FuzzRegressions, MiddleburyImageNameTooLongForTheFilesystemIsAnErrorNotACrash) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::temp_directory_path() / "subflow_fuzz_regression_long_name";
  fs::create_directories(folder);
  const fs::path file = folder / "scene_par.txt";
  {
    std::ofstream out(file);
    out << "1\n" << std::string(300, 'x') << ".png 1 0 0 0 1 0 0 0 1 1 0 0 0 1 0 0 0 1 0 0 0\n";
  }
  std::string message = "no error";
  try {
    ReadMiddleburyParameters(file.string(), ProjectionMatrixImportOptions{});
  } catch (const Error& e) {
    message = e.what();
  }  // any other exception fails the test by escaping
  fs::remove_all(folder);
  EXPECT_EQ(message.rfind(file.string() + ":", 0), 0u) << message;
}

}  // namespace
}  // namespace subflow::vision
