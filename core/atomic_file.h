// Writing a file so that no reader ever sees it half-written: everything goes to a
// temporary ".<name>.partial" beside it (a name no reader of subflow accepts: hidden, and
// not ending in any extension a reader takes), renamed to the final name by Commit()
// once complete. An AtomicFile destroyed before Commit() — an error, an interruption
// (core/interrupt.h) — removes its temporary. A process killed outright (SIGKILL) can
// leave a ".<name>.partial", visibly unfinished; never a file with the final name.
// Commit() also makes the file durable before it counts as written: the temporary's data
// are flushed to the disk (fsync) before the rename, and the directory after it, so that
// after a crash of the machine (power loss) the final name holds the complete file or
// nothing — never an empty or partial file, which a rename alone allows on ext4 / XFS
// with delayed allocation. A report.json committed last is thus never durable before the
// files it describes.
//
// The one mechanism for every file subflow writes:
//   AtomicFile file(path);                       // a stream
//   file.stream() << text;
//   file.Commit();
// or, for a library that opens the file itself and picks the format from the extension
// (cv::VideoWriter), a temporary that keeps the extension, ".<stem>.partial<.ext>":
//   AtomicFile file(path, AtomicFile::kKeepExtension);
//   writer.open(file.temporary(), ...); ... writer.release();
//   file.Commit();
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "core/error.h"

namespace subflow {

class AtomicFile {
 public:
  enum TemporaryName { kPartialSuffix, kKeepExtension };

  // Chooses the temporary name (nothing is created yet: stream() opens it).
  explicit AtomicFile(std::string path, TemporaryName naming = kPartialSuffix)
      : path_(std::move(path)), temporary_(TemporaryPath(path_, naming)) {}
  ~AtomicFile() {
    if (committed_) return;
    if (stream_.is_open()) stream_.close();
    std::error_code ignored;  // a destructor must not throw
    std::filesystem::remove(temporary_, ignored);
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // The binary stream to the temporary, opened (truncated) on first use; throws
  // subflow::Error naming the final path when it cannot be opened.
  std::ofstream& stream() {
    if (!stream_.is_open()) {
      stream_.open(temporary_, std::ios::binary | std::ios::trunc);
      if (!stream_)
        ThrowError(path_, "", "cannot open \"" + temporary_ + "\" for writing: " + std::strerror(errno));
    }
    return stream_;
  }
  const std::string& path() const { return path_; }
  const std::string& temporary() const { return temporary_; }

  // Flushes and closes the stream (if used), checks that the temporary exists and renames
  // it to path(); throws subflow::Error naming path() on failure (the temporary removed).
  void Commit() {
    std::error_code error;
    if (stream_.is_open()) {
      stream_.flush();
      const bool written = static_cast<bool>(stream_);
      stream_.close();
      if (!written || stream_.fail()) ThrowError(path_, "", "write failed (disk full?)");
    }
    if (!std::filesystem::is_regular_file(temporary_, error))
      ThrowError(path_, "", "was not written (no \"" + temporary_ + "\")");
    Sync(temporary_, false);
    std::filesystem::rename(temporary_, path_, error);
    if (error) ThrowError(path_, "", "cannot rename \"" + temporary_ + "\" into place: " + error.message());
    committed_ = true;
    const std::filesystem::path directory = std::filesystem::path(path_).parent_path();
    Sync(directory.empty() ? "." : directory.string(), true);
  }

  // ".<name>.partial", or ".<stem>.partial<.ext>" with kKeepExtension, in path's directory.
  static std::string TemporaryPath(const std::string& path, TemporaryName naming) {
    const std::filesystem::path final_path(path);
    const std::string name = naming == kKeepExtension
                                 ? final_path.stem().string() + ".partial" + final_path.extension().string()
                                 : final_path.filename().string() + ".partial";
    return (final_path.parent_path() / ("." + name)).string();
  }

 private:
  // fsync of the file or directory `path`: its data (a file) or its entries (a directory)
  // on the disk. Throws subflow::Error naming path() when the disk reports an error; a
  // file system that cannot sync (EINVAL, EROFS: /proc, some FUSE mounts) is no error.
  void Sync(const std::string& path, bool directory) const {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (directory ? O_DIRECTORY : 0));
    if (fd < 0) ThrowError(path_, "", "cannot open \"" + path + "\" to flush it: " + std::strerror(errno));
    const int status = ::fsync(fd);
    const int error = errno;
    ::close(fd);
    if (status != 0 && error != EINVAL && error != EROFS)
      ThrowError(path_, "", "cannot flush \"" + path + "\" to the disk: " + std::strerror(error));
  }

  std::string path_, temporary_;
  std::ofstream stream_;
  bool committed_ = false;
};

// Writes `bytes` to `path` through an AtomicFile.
inline void WriteFileAtomically(const std::string& path, std::string_view bytes) {
  AtomicFile file(path);
  file.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  file.Commit();
}

}  // namespace subflow
