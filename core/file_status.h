// What a path of a user's input is, for the readers, without std::filesystem's throwing
// forms: fs::exists / is_directory / is_regular_file throw filesystem_error on a link loop,
// a name too long or a folder without permission, which ends a reader with an exception
// that is not a subflow::Error. Here such a path is an error naming it and the reason
// ("too many levels of symbolic links"), and a link to nothing is told apart from no entry,
// so that a reader can say that a file it was given is broken instead of absent.
#pragma once

#include <filesystem>
#include <string>
#include <system_error>

#include "core/error.h"

namespace subflow {

enum class PathKind { kMissing, kDanglingLink, kFile, kDirectory, kOther };

// The kind of what `path` names, links followed; throws subflow::Error naming `path` when
// it cannot be examined.
inline PathKind KindOfPath(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (status.type() == fs::file_type::not_found || error == std::errc::no_such_file_or_directory ||
      error == std::errc::not_a_directory) {
    std::error_code link_error;
    return fs::is_symlink(fs::symlink_status(path, link_error)) ? PathKind::kDanglingLink : PathKind::kMissing;
  }
  if (error) ThrowError(path.string(), "", "cannot be examined: " + error.message());
  if (fs::is_regular_file(status)) return PathKind::kFile;
  if (fs::is_directory(status)) return PathKind::kDirectory;
  return PathKind::kOther;
}

inline bool IsFile(const std::filesystem::path& path) { return KindOfPath(path) == PathKind::kFile; }
inline bool IsDirectory(const std::filesystem::path& path) { return KindOfPath(path) == PathKind::kDirectory; }
// An entry is there: a file, a folder, anything, or a link to nothing (which is meant as
// one, and is reported when read).
inline bool EntryExists(const std::filesystem::path& path) { return KindOfPath(path) != PathKind::kMissing; }

}  // namespace subflow
