// Every reader against inputs nobody wrote on purpose: each valid seed of the fuzz corpora
// (fuzz/corpus/<harness>/, laid out with fuzz/fuzz_support.h) is broken one file at a time,
// in the ways a user's disk or tool breaks files, and read again. The rules:
//   - the file empty, a directory, a symbolic link to itself (a loop) or to nothing, or
//     unreadable: refused with a subflow::Error that names the file;
//   - a number of a text file replaced by NaN, infinity, a value beyond double's range, a
//     huge integer (an absurd size or count) or a word (a wrong type), or the file cut
//     short: either refused with a subflow::Error naming a file of the input, or read into
//     a result whose numbers are all finite (the number was one the reader does not use,
//     or the cut fell between records);
//   - nothing else: no other exception (std::bad_alloc from a size believed, nlohmann's or
//     std::filesystem's own), no NaN let through, no crash (the sanitizer build runs this).
// A reader added to the fuzz harnesses belongs in the table below.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "fuzz/fuzz_support.h"
#include "geometry/mesh_io.h"
#include "output/result_reader.h"
#include "tests/test_support.h"
#include "vision/dataset.h"
#include "vision/import_colmap.h"
#include "vision/import_projection_matrices.h"
#include "vision/read_calibration.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

// A reader's output held a NaN or an infinity.
struct NonFiniteOutput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

template <class Matrix>
void RequireFinite(const Matrix& m, const std::string& what) {
  if (!m.allFinite()) throw NonFiniteOutput(what + " holds NaN or infinity");
}

void RequireFinite(const vision::Camera& camera) {
  RequireFinite(camera.K(), camera.name() + " K");
  RequireFinite(camera.R(), camera.name() + " R");
  RequireFinite(camera.t(), camera.name() + " t");
  RequireFinite(camera.distortion(), camera.name() + " distortion");
}

void ReadMeshFinite(const fs::path& path) {
  geometry::VertexProperties properties;
  const geometry::TriangleMesh mesh = geometry::ReadMesh(path.string(), {}, &properties);
  RequireFinite(mesh.V, "V");
  for (const auto& [name, values] : properties.values) RequireFinite(values, name);
}

void ReadCalibrationFinite(const std::string& format, const fs::path& source) {
  vision::CalibrationReadOptions options;
  options.colmap_names = "folder";  // the seeds' images are <camera>/<frame>.png
  for (const vision::CalibratedCamera& camera : vision::ReadCalibration(format, source.string(), options).cameras) {
    RequireFinite(camera.K, camera.name + " K");
    RequireFinite(camera.R, camera.name + " R");
    RequireFinite(camera.t, camera.name + " t");
    RequireFinite(camera.distortion, camera.name + " distortion");
  }
}

void ReadDatasetFinite(const fs::path& root) {
  const vision::Dataset dataset(root.string());
  for (int c = 0; c < dataset.camera_count(); ++c) {
    RequireFinite(dataset.camera(c));
    for (int f = 0; f < dataset.frame_count(); ++f) {
      dataset.Gray(c, f);
      if (dataset.has_masks()) dataset.Mask(c, f);
    }
    if (dataset.has_background()) dataset.BackgroundGray(c);
  }
  if (dataset.has_groundtruth())  // read by `subflow eval` with the mesh reader
    for (int f = 0; f < dataset.frame_count(); ++f) ReadMeshFinite(dataset.GroundTruthMeshPath(f));
}

void ReadResultFinite(const fs::path& root) {
  const output::ResultReader reader(root.string());
  for (int i = 0; i < reader.frame_count(); ++i) {
    const output::ResultFrame frame = reader.ReadFrame(i);
    RequireFinite(frame.V, reader.MeshPath(i));
    for (const auto& [name, values] : frame.properties.values) RequireFinite(values, reader.MeshPath(i) + " " + name);
  }
}

struct Reader {
  std::string seed;       // fuzz/corpus/<harness>/<seed>
  std::string file_name;  // a single-file seed is written under this name; "" = a file tree
  std::function<void(const fs::path& root)> read;
};

std::vector<Reader> Readers() {
  const auto mesh = [](const std::string& name) {
    return [name](const fs::path& root) { ReadMeshFinite(root / name); };
  };
  const auto calibration = [](const std::string& format, const std::string& file) {
    return [format, file](const fs::path& root) { ReadCalibrationFinite(format, file.empty() ? root : root / file); };
  };
  const auto cameras = [](const fs::path& root) {
    vision::DatasetInfo info;
    for (const vision::Camera& camera : vision::ReadCamerasJson((root / "cameras.json").string(), &info))
      RequireFinite(camera);
  };
  std::vector<Reader> readers = {
      {"cameras_json_fuzzer/small.json", "cameras.json", cameras},
      {"cameras_json_fuzzer/no_bounds.json", "cameras.json", cameras},
      {"cameras_json_fuzzer/blob.json", "cameras.json", cameras},
      {"ply_fuzzer/tetra_ascii.ply", "mesh.ply", mesh("mesh.ply")},
      {"ply_fuzzer/cube_quads_ascii.ply", "mesh.ply", mesh("mesh.ply")},
      {"ply_fuzzer/tetra_le.ply", "mesh.ply", mesh("mesh.ply")},
      {"ply_fuzzer/cube_quads_be.ply", "mesh.ply", mesh("mesh.ply")},
      {"ply_fuzzer/tetra_be_ushort.ply", "mesh.ply", mesh("mesh.ply")},
      {"obj_fuzzer/tetra.obj", "mesh.obj", mesh("mesh.obj")},
      {"obj_fuzzer/cube_quads.obj", "mesh.obj", mesh("mesh.obj")},
      {"obj_fuzzer/tetra_relative.obj", "mesh.obj", mesh("mesh.obj")},
      {"obj_fuzzer/lshape_ngon.obj", "mesh.obj", mesh("mesh.obj")},
      {"calibration_fuzzer/colmap", "", calibration("colmap", "")},
      {"calibration_fuzzer/colmap_binary", "", calibration("colmap", "")},
      {"calibration_fuzzer/dtu_folder", "", calibration("matrices", "")},
      {"calibration_fuzzer/pose2sim_toml", "", calibration("toml", "Calib.toml")},
      {"calibration_fuzzer/panoptic_json", "", calibration("panoptic", "calibration.json")},
      {"calibration_fuzzer/qualisys_qca", "", calibration("qualisys", "Calib.qca.txt")},
      {"calibration_fuzzer/easymocap_yml", "", calibration("easymocap", "")},
      {"projection_matrix_fuzzer/middlebury", "", calibration("middlebury", "scene_par.txt")},
      {"colmap_text_fuzzer/three_models", "",
       [](const fs::path& root) {
         vision::ColmapImportOptions options;
         options.name_from = vision::ColmapImportOptions::NameFrom::kParentFolder;
         for (const vision::Camera& camera : vision::ReadColmapTextModel(root.string(), options)) RequireFinite(camera);
       }},
      {"dataset_layout_fuzzer/images_masks_background", "", ReadDatasetFinite},
      {"dataset_layout_fuzzer/rgba_groundtruth", "", ReadDatasetFinite},
      {"result_reader_fuzzer/two_frames", "", ReadResultFinite},
  };
  return readers;
}

// The seed laid out in a fresh folder `root`.
void LayOut(const Reader& reader, const fs::path& root) {
  fs::remove_all(root);
  fs::create_directories(root);
  const std::string bytes = test::ReadTextFile(fs::path(SUBFLOW_SOURCE_DIR) / "fuzz" / "corpus" / reader.seed);
  if (!reader.file_name.empty())
    fuzz::WriteFile(root / reader.file_name, bytes);
  else
    fuzz::WriteFileTree(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), root);
}

std::vector<fs::path> FilesOf(const fs::path& root) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    if (entry.is_regular_file()) files.push_back(fs::relative(entry.path(), root));
  std::sort(files.begin(), files.end());
  return files;
}

bool IsText(const std::string& bytes) { return bytes.find('\0') == std::string::npos && bytes.rfind("\x89PNG", 0) != 0; }

// One way of breaking a file, and what must come of reading it.
struct Breakage {
  std::string what;
  bool must_refuse;  // true: a subflow::Error naming the file; false: that or a finite result
};

struct Outcome {
  bool refused = false;
  std::string problem;  // "" when the outcome follows the rules of the file comment
};

// Reads the input below `root` broken by `breakage` of `file`.
Outcome Read(const Reader& reader, const fs::path& root, const fs::path& file, const Breakage& breakage) {
  std::string problem;
  bool refused = false;
  try {
    reader.read(root);
    if (breakage.must_refuse) problem = "read without an error";
  } catch (const Error& e) {
    refused = true;
    const std::string message = e.what();
    const std::string named = breakage.must_refuse ? file.filename().string() : root.string();
    if (message.find(named) == std::string::npos && (breakage.must_refuse || message.find(reader.file_name) == std::string::npos))
      problem = "the error does not name " + named + ": " + message;
  } catch (const NonFiniteOutput& e) {
    problem = std::string("NaN or infinity let through: ") + e.what();
  } catch (const std::exception& e) {
    problem = std::string("an exception other than subflow::Error: ") + typeid(e).name() + ": " + e.what();
  }
  return {refused, problem.empty() ? "" : reader.seed + ", " + file.string() + " " + breakage.what + ": " + problem};
}

// Numbers of a text file: [start, length) of each.
std::vector<std::pair<std::size_t, std::size_t>> Numbers(const std::string& text) {
  static const std::regex number(R"((^|[\s\[\]{},=:"'(])([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)(?=[\s\[\]{},"';)]|$))");
  std::vector<std::pair<std::size_t, std::size_t>> found;
  for (std::sregex_iterator it(text.begin(), text.end(), number), end; it != end; ++it)
    found.emplace_back(static_cast<std::size_t>(it->position(2)), static_cast<std::size_t>(it->length(2)));
  return found;
}

class BrokenInputs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { spdlog::set_level(spdlog::level::off); }
  static void TearDownTestSuite() { spdlog::set_level(spdlog::level::info); }
};

// Each seed reads as it is (else the breakages below would test nothing).
TEST_F(BrokenInputs, EverySeedReads) {
  const test::TemporaryDirectory scratch("broken_inputs_seeds");
  for (const Reader& reader : Readers()) {
    LayOut(reader, scratch / "input");
    EXPECT_NO_THROW(reader.read(scratch / "input")) << reader.seed;
  }
}

TEST_F(BrokenInputs, AFileThatIsEmptyADirectoryALinkLoopOrUnreadableIsRefusedByName) {
  const test::TemporaryDirectory scratch("broken_inputs_files");
  const fs::path root = scratch / "input";
  std::vector<std::string> problems;
  int cases = 0;
  for (const Reader& reader : Readers()) {
    LayOut(reader, root);
    for (const fs::path& file : FilesOf(root)) {
      const fs::path path = root / file;
      const auto check = [&](const std::string& what, const std::function<void()>& breaking) {
        LayOut(reader, root);
        breaking();
        const Outcome outcome = Read(reader, root, file, {what, true});
        if (!outcome.problem.empty()) problems.push_back(outcome.problem);
        ++cases;
      };
      check("empty", [&] { std::ofstream(path, std::ios::trunc); });
      check("a directory", [&] { fs::remove(path); fs::create_directory(path); });
      check("a link to itself", [&] { fs::remove(path); fs::create_symlink(path.filename(), path); });
      check("a link to nothing", [&] { fs::remove(path); fs::create_symlink("missing", path); });
      if (geteuid() != 0)  // root reads a file whatever its mode
        check("unreadable", [&] { fs::permissions(path, fs::perms::none); });
    }
  }
  fs::remove_all(root);
  std::string list;
  for (const std::string& problem : problems) list += "\n  " + problem;
  EXPECT_TRUE(problems.empty()) << problems.size() << " of " << cases << " cases:" << list;
  if (geteuid() == 0) std::cout << "[ NOTE     ] unreadable files not tried: running as root\n";
}

TEST_F(BrokenInputs, NonFiniteHugeOrMistypedNumbersAndCutFilesAreRefusedOrHarmless) {
  const test::TemporaryDirectory scratch("broken_inputs_numbers");
  const fs::path root = scratch / "input";
  std::vector<std::string> problems;
  int cases = 0, refused = 0;
  for (const Reader& reader : Readers()) {
    LayOut(reader, root);
    for (const fs::path& file : FilesOf(root)) {
      const std::string original = test::ReadTextFile(root / file);
      const auto check = [&](const std::string& what, const std::string& bytes) {
        LayOut(reader, root);
        fuzz::WriteFile(root / file, bytes);
        const Outcome outcome = Read(reader, root, file, {what, false});
        if (!outcome.problem.empty()) problems.push_back(outcome.problem);
        refused += outcome.refused;
        ++cases;
      };
      for (const double fraction : {0.25, 0.5, 0.75})
        check("cut at " + std::to_string(static_cast<int>(fraction * 100)) + " %",
              original.substr(0, static_cast<std::size_t>(fraction * original.size())));
      if (!IsText(original)) continue;
      for (const auto& [start, length] : Numbers(original)) {
        const std::string number = original.substr(start, length);
        for (const char* replacement : {"nan", "inf", "-inf", "1e999", "99999999999", "2147483648", "x"})
          check("number \"" + number + "\" at byte " + std::to_string(start) + " → " + replacement,
                original.substr(0, start) + replacement + original.substr(start + length));
      }
    }
  }
  fs::remove_all(root);
  std::string list;
  for (std::size_t i = 0; i < problems.size() && i < 60; ++i) list += "\n  " + problems[i];
  EXPECT_TRUE(problems.empty()) << problems.size() << " of " << cases << " cases:" << list;
  std::cout << "[ NOTE     ] " << cases << " broken inputs, " << refused << " refused, the rest read finite\n";
}

}  // namespace
}  // namespace subflow
