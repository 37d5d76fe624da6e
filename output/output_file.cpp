#include "output/output_file.h"

#include <filesystem>

#include "core/error.h"

namespace subflow::output {

namespace fs = std::filesystem;

void CheckOutputPath(const std::string& path, bool overwrite) {
  std::error_code error;
  if (fs::is_directory(path, error)) ThrowError(path, "", "is a directory (expected a file name)");
  if (fs::exists(path, error) && !overwrite)
    ThrowError(path, "", "exists; choose another name or pass --overwrite");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent, error))
    ThrowError(path, "", "the directory " + parent.string() + " does not exist");
}

OutputFile::OutputFile(const std::string& path) : path_(path), temporary_(path + ".tmp") {
  stream_.open(temporary_, std::ios::binary | std::ios::trunc);
  if (!stream_) ThrowError(path, "", "cannot open " + temporary_ + " for writing");
}

OutputFile::~OutputFile() {
  if (committed_) return;
  stream_.close();
  std::error_code ignored;  // a destructor must not throw
  fs::remove(temporary_, ignored);
}

void OutputFile::Commit() {
  stream_.flush();
  if (!stream_) ThrowError(path_, "", "write failed (disk full?)");
  stream_.close();
  std::error_code error;
  fs::rename(temporary_, path_, error);
  if (error) ThrowError(path_, "", "cannot rename the temporary file: " + error.message());
  committed_ = true;
}

}  // namespace subflow::output
