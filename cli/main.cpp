// subflow: multi-view video → time-varying Loop subdivision surface with scene flow.
// Each subcommand lives in its own file and registers itself through cli/commands.h.
#include <vector>

#include <malloc.h>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "cli/commands.h"

namespace {
// The solvers allocate and free arrays of megabytes on every step (sample and constraint
// arrays, CG vectors, Ceres's Jacobians). glibc gives blocks above its mmap threshold
// (dynamic, at most 32 MB) and a heap top above its trim threshold back to the kernel at
// once, and the next step faults every page in again: on this paravirtualized machine that
// was ~10 % of a stage's time in the kernel (docs/speed.md, "Memory given back and faulted
// in again"). Freed blocks up to 256 MB now stay in the process, and the next step's
// arrays of the same sizes reuse them. Measured peak: blob 0.97 → 0.99 GB, pose2sim
// 3.80 → 3.69 GB.
void KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
}
}  // namespace

int main(int argc, char** argv) {
  KeepFreedMemoryForReuse();
  CLI::App app{"subflow " SUBFLOW_VERSION
               " — spatio-temporal stereo with multi-resolution Loop subdivision surfaces"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("subflow ") + SUBFLOW_VERSION);
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Log debug messages");
  std::vector<subflow::cli::Command> commands;
  for (auto add_command : subflow::cli::AllCommands()) commands.push_back(add_command(app));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return subflow::cli::RunSelected(commands, verbose);
}
