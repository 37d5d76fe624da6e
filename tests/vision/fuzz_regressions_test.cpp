// Inputs the fuzz harnesses (fuzz/) found to break a reader, each now an error naming the
// file and the field (the inputs are also seeds in fuzz/corpus/).
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "vision/import_panoptic.h"

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

}  // namespace
}  // namespace subflow::vision
