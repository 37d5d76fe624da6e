// Claims about reading cameras.json (vision/dataset.h, core/json_reader.h): every failure,
// syntax or value, comes out as one line "<file>: <field>: <what was expected>" — numbers
// beyond double's range (1e999), the NaN / Infinity literals JSON does not have, sizes
// and counts too large to allocate, duplicate keys, deep nesting — and never as an
// nlohmann exception without the file and the field.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/json_reader.h"
#include "tests/test_support.h"
#include "vision/dataset.h"

namespace subflow::vision {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("cameras_json_test");
  return scratch;
}

// One valid camera; `K00`, `width` and `extra` are spliced into the text as written.
std::string CamerasJson(const std::string& K00 = "400.0", const std::string& width = "64",
                        const std::string& extra = "") {
  return "{\n \"format\": \"multiview-video/1\",\n \"fps\": 30," + extra +
         "\n \"cameras\": [\n  {\"name\": \"cam0\", \"width\": " + width +
         ", \"height\": 48,\n   \"K\": [[" + K00 +
         ", 0, 31.5], [0, 400, 23.5], [0, 0, 1]],\n"
         "   \"R\": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], \"t\": [0, 0, 2]}\n ]\n}\n";
}

// The one-line message of reading `text` as cameras.json ("no error" when it reads).
std::string ReadError(const std::string& text, std::string* path_out = nullptr) {
  static int count = 0;
  const fs::path path = Scratch() / ("cameras_" + std::to_string(count++) + ".json");
  std::ofstream(path, std::ios::binary) << text;
  if (path_out) *path_out = path.string();
  try {
    ReadCamerasJson(path.string());
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("not a subflow::Error: ") + e.what();
  }
  return "no error";
}

// The message starts with the file, names the field, says what was expected, is one line.
void ExpectFileFieldExpectation(const std::string& text, const std::string& field,
                                const std::string& expectation) {
  std::string path;
  const std::string message = ReadError(text, &path);
  EXPECT_EQ(message.rfind(path + ": " + field + ": ", 0), 0u) << message;
  EXPECT_NE(message.find(expectation), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.find("json.exception"), std::string::npos) << message;
  EXPECT_LT(message.size(), 400u) << message;
}

TEST(CamerasJson, TheValidDocumentReads) { EXPECT_EQ(ReadError(CamerasJson()), "no error"); }

TEST(CamerasJson, NumberBeyondDoubleRangeNamesFileFieldAndExpectation) {
  ExpectFileFieldExpectation(CamerasJson("1e999"), "cameras[0].K[0][0]", "expected a finite number");
  ExpectFileFieldExpectation(CamerasJson("-1e999"), "cameras[0].K[0][0]", "number overflow");
  ExpectFileFieldExpectation(CamerasJson("400", "64", "\n \"frame_count\": 1e400,"), "frame_count",
                             "expected a finite number");
}

TEST(CamerasJson, NanAndInfinityLiteralsAreSyntaxErrorsAtTheirField) {
  for (const std::string literal : {"NaN", "nan", "Infinity", "-Infinity", "inf"})
    ExpectFileFieldExpectation(CamerasJson(literal), "cameras[0].K[0][0]", "invalid JSON at line 6");
}

TEST(CamerasJson, SizesAndCountsBeyondTheLimitsAreRefused) {
  ExpectFileFieldExpectation(CamerasJson("400", "100000"), "cameras[0] (\"cam0\").width",
                             "expected an integer in [1, 32768]");
  ExpectFileFieldExpectation(CamerasJson("400", "18446744073709551616"), "cameras[0] (\"cam0\").width",
                             "expected an integer in [1, 32768]");
  // Each side within the limit, but 2^30 pixels: refused before any image is allocated.
  std::string square = CamerasJson("400", "32768");
  square.replace(square.find("\"height\": 48"), 12, "\"height\": 32768");
  ExpectFileFieldExpectation(square, "camera \"cam0\": width × height", "expected at most 268435456 pixels");
  ExpectFileFieldExpectation(CamerasJson("400", "64.5"), "cameras[0] (\"cam0\").width",
                             "expected an integer");
  ExpectFileFieldExpectation(CamerasJson("400", "64", "\n \"frame_count\": 1000000000,"), "frame_count",
                             "expected an integer in [1, 1000000]");
}

TEST(CamerasJson, DuplicateKeysAndDeepNestingAreRefused) {
  ExpectFileFieldExpectation(CamerasJson("400", "64", "\n \"fps\": 25,"), "fps", "duplicate key \"fps\"");
  const std::string deep = "{\"format\": \"multiview-video/1\", \"units\": " + std::string(100, '[') +
                           std::string(100, ']') + "}";
  std::string deepest = "units";
  for (int level = 0; level < kMaxJsonDepth - 1; ++level) deepest += "[0]";
  ExpectFileFieldExpectation(deep, deepest, "nesting deeper than 64");
}

TEST(CamerasJson, SyntaxErrorsGiveLineColumnAndTheFieldBeingRead) {
  std::string text = CamerasJson();
  text.resize(text.find("\"R\""));  // cut inside camera 0
  ExpectFileFieldExpectation(text, "cameras[0].K", "invalid JSON at line");
  ExpectFileFieldExpectation("", "(top level)", "expected the dataset's cameras.json");
  ExpectFileFieldExpectation("\xff\xfe{}", "(top level)", "invalid JSON at line 1");
  ExpectFileFieldExpectation("[1, 2]", "(top level)", "expected a JSON object, got array");
}

TEST(CamerasJson, WrongTypesNameTheFieldAndShowAShortValue) {
  std::string huge = "\"" + std::string(100000, 'x') + "\"";
  ExpectFileFieldExpectation(CamerasJson(huge), "cameras[0] (\"cam0\").K[0][0]", "expected a number, got string");
  ExpectFileFieldExpectation(CamerasJson("[1]"), "cameras[0] (\"cam0\").K[0][0]", "expected a number, got array");
}

TEST(JsonReader, IntegerRangesAndFiniteNumbersAreChecked) {
  const JsonReader reader("doc.json");
  const nlohmann::json doc = ParseJson(R"({"a": 5, "b": -3, "c": 2.5, "d": 1e300})", "doc.json", "a test document");
  EXPECT_EQ(reader.Integer(doc["a"], "a", 0, 10), 5);
  EXPECT_THROW(reader.Integer(doc["b"], "b", 0, 10), Error);
  EXPECT_THROW(reader.Integer(doc["c"], "c", 0, 10), Error);
  EXPECT_DOUBLE_EQ(reader.Number(doc["d"], "d"), 1e300);
  try {
    reader.Required(doc, "e", "");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "doc.json: e: missing required field \"e\"");
  }
}

}  // namespace
}  // namespace subflow::vision
