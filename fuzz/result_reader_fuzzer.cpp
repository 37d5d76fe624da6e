// libFuzzer harness: the result reader of `eval` and `export` (output/result_reader.h) on a
// fuzzed result folder (fuzz/fuzz_support.h): meshes/<frame>.ply and report.json, every
// frame read.
#include "fuzz/fuzz_support.h"
#include "output/result_reader.h"

SUBFLOW_FUZZ_QUIET_INITIALIZE()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto root = subflow::fuzz::TreeOfInput(data, size);
  subflow::fuzz::RunReader([&] { subflow::output::CheckResultFolder(root.string()); });
  return 0;
}
