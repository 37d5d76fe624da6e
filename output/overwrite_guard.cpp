#include "output/overwrite_guard.h"

#include <filesystem>

#include "core/error.h"

namespace subflow::output {

void CheckOutputFile(const std::string& path, bool overwrite, const std::string& flag) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (fs::is_directory(status))
    ThrowError(path, flag, "is a directory (expected the path of a file to write)");
  if (fs::exists(status) && !overwrite)
    ThrowError(path, flag, "exists; refusing to overwrite it (choose another path or pass --overwrite)");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent, error))
    ThrowError(path, flag, "directory \"" + parent.string() + "\" does not exist");
}

}  // namespace subflow::output
