// Writing one user-facing file safely: nothing the user had is replaced unless asked
// (CheckOutputPath), and a file that is not finished never carries the final name
// (OutputFile writes "<path>.tmp" and renames it on Commit; a destroyed, uncommitted
// OutputFile removes its temporary).
#pragma once

#include <fstream>
#include <string>

namespace subflow::output {

// Throws subflow::Error naming `path` when it exists and `overwrite` is false ("exists;
// pass --overwrite"), when it is a directory, or when its parent directory does not exist.
void CheckOutputPath(const std::string& path, bool overwrite);

class OutputFile {
 public:
  // Opens "<path>.tmp" for binary writing; throws subflow::Error naming `path` on failure.
  explicit OutputFile(const std::string& path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  std::ofstream& stream() { return stream_; }
  const std::string& path() const { return path_; }
  // Flushes, checks the stream and renames the temporary to `path`; throws on failure.
  void Commit();

 private:
  std::string path_, temporary_;
  std::ofstream stream_;
  bool committed_ = false;
};

}  // namespace subflow::output
