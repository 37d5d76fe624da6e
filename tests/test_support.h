// Helpers shared by the GoogleTest executables: scratch directories, reading files back,
// and running the `subflow` command. Header-only, because every test file is its own
// executable (tests/CMakeLists.txt).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include "geometry/triangle_mesh.h"

namespace subflow::test {

// The whole content of a file ("" when it cannot be opened).
inline std::string ReadTextFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A fresh, empty directory <system temp>/subflow_<name>_<pid>, removed with its content
// when the object is destroyed. The process id keeps concurrent runs (ctest -j) apart;
// `name` keeps the test files (and tests of one file) apart. A test file that wants one
// directory for the whole run holds it in a function-local static (removed at exit).
class TemporaryDirectory {
 public:
  explicit TemporaryDirectory(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("subflow_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TemporaryDirectory() {
    std::error_code ignored;  // a destructor must not throw
    std::filesystem::remove_all(path_, ignored);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string string() const { return path_.string(); }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

  // A path `name` below the directory that does not exist (removed if it does), for
  // code that must create its output directory itself.
  std::filesystem::path FreshPath(const std::string& name) const {
    const std::filesystem::path fresh = path_ / name;
    std::filesystem::remove_all(fresh);
    return fresh;
  }
  // A fresh, empty subdirectory `name` (emptied when it exists already).
  std::filesystem::path Subdirectory(const std::string& name) const {
    const std::filesystem::path directory = path_ / name;
    std::filesystem::remove_all(directory);
    std::filesystem::create_directories(directory);
    return directory;
  }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_code = -1;  // −1 when the command did not exit normally (e.g. a signal)
  std::string out, err;
  std::string output() const { return out + err; }  // both streams, stdout first
};

// SUBFLOW_BINARY, the path of the built `subflow`, is defined only for the test files
// that run it (tests/cli/ and SUBFLOW_COMMAND_TESTS in tests/CMakeLists.txt), which also
// depend on the binary so that building them brings it up to date.
#ifdef SUBFLOW_BINARY
// Runs `subflow ARGUMENTS` through the shell (the caller quotes paths in ARGUMENTS) and
// captures stdout and stderr, through the files stdout and stderr in `scratch`.
inline CommandResult RunSubflow(const std::string& arguments,
                                const std::filesystem::path& scratch) {
  const std::filesystem::path out = scratch / "stdout", err = scratch / "stderr";
  const std::string command = std::string("'") + SUBFLOW_BINARY + "' " + arguments + " >'" +
                              out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(command.c_str());
  CommandResult run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = ReadTextFile(out);
  run.err = ReadTextFile(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return run;
}

// The small deforming blob the reconstruct tests run on (6 gray cameras, `frames` frames,
// 160×120), written by `subflow synth` to <scratch>/blob.
inline std::filesystem::path SynthSmallBlob(const TemporaryDirectory& scratch, int frames = 3) {
  const std::filesystem::path path = scratch / "blob";
  const CommandResult run = RunSubflow("synth blob --out '" + path.string() + "' --cameras 6 --frames " +
                                           std::to_string(frames) + " --width 160 --height 120 --subdivisions 4 --gray",
                                       scratch.path());
  if (run.exit_code != 0) throw std::runtime_error("subflow synth failed: " + run.output());
  return path;
}
#endif

// `mesh` with every vertex coordinate moved by a uniform random offset in
// [−amplitude, amplitude] (std::mt19937 seeded with `seed`, so reproducible): generic
// geometry, so that no symmetry hides a wrong weight or index.
inline geometry::TriangleMesh Perturbed(geometry::TriangleMesh mesh, double amplitude,
                                        unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> offset(-amplitude, amplitude);
  for (Eigen::Index v = 0; v < mesh.V.rows(); ++v)
    for (int k = 0; k < 3; ++k) mesh.V(v, k) += offset(random);
  return mesh;
}

}  // namespace subflow::test
