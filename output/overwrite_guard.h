// Commands never replace what the user has unless told to: every file or directory a
// command writes is checked before any work starts, and an existing one is refused
// without --overwrite. (Result directories: PrepareOutputDirectory, output/result_writer.h.)
#pragma once

#include <string>

namespace subflow::output {

// Checks that `path` may be written as a new file: throws subflow::Error naming it (and
// `flag`, the option that named it, e.g. "--out") when it exists and `overwrite` is false,
// when it is a directory, or when its directory does not exist.
void CheckOutputFile(const std::string& path, bool overwrite, const std::string& flag);

}  // namespace subflow::output
