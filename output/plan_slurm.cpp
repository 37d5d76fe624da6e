// WriteSlurmScripts (declared in output/plan.h).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "core/error.h"
#include "core/json_reader.h"
#include "core/atomic_file.h"
#include "output/plan.h"

namespace subflow::output {

namespace fs = std::filesystem;

namespace {

// The memory to request for `task` (MiB): `fixed`, else 1.5 × the peak a finished run-plan
// of this plan measured (status/<id>.json, when measured for the task as this plan defines
// it: a re-planned task's memory may differ), else kDefaultTaskMemoryMiB.
int TaskMemoryMiB(const std::string& directory, const nlohmann::json& task, int fixed) {
  if (fixed > 0) return fixed;
  const fs::path status = fs::path(directory) / "status" / (task.at("id").get<std::string>() + ".json");
  if (fs::is_regular_file(status)) {
    const nlohmann::json measured = ReadJsonFile(status.string(), "a task status (subflow run-plan)");
    const bool same_task = measured.value("stamp", std::string()) == task.value("stamp", std::string());
    const double kib = same_task ? measured.value("max_rss_kib", 0.0) : 0.0;
    if (kib > 0) return std::max(256, static_cast<int>(std::ceil(1.5 * kib / 1024.0)));
  }
  return kDefaultTaskMemoryMiB;
}

void WriteText(const fs::path& path, const std::string& text, bool executable) {
  AtomicFile file(path.string());
  file.stream() << text;
  file.Commit();
  if (executable)
    fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                    fs::perm_options::add);
}

// The shell variable holding the job id of task `id`.
std::string JobVariable(const std::string& id) { return "job_" + id; }

}  // namespace

void WriteSlurmScripts(const std::string& directory, const nlohmann::json& plan, int memory_mib) {
  const fs::path slurm = fs::path(directory) / "slurm";
  fs::create_directories(slurm);
  const std::string binary = fs::read_symlink("/proc/self/exe").string();
  // One script runs any task by its id (the array script: refine_<index>).
  const std::string head = "#!/bin/bash\n#SBATCH --output=" + (slurm / "%x_%A_%a.log").string() +
                           "\n#SBATCH --ntasks=1\nset -euo pipefail\n";
  WriteText(slurm / "task.sbatch",
            head + "# Runs one task of the plan (skipped when its output is complete).\n\"" + binary +
                "\" run-plan \"" + directory + "\" --task \"$1\"\n",
            true);
  WriteText(slurm / "refine_array.sbatch",
            head + "# The refinement chunks as a job array: task refine_<SLURM_ARRAY_TASK_ID>.\n\"" + binary +
                "\" run-plan \"" + directory + "\" --task \"refine_${SLURM_ARRAY_TASK_ID}\"\n",
            true);

  std::string submit = "#!/bin/bash\n# Submits the plan " + directory +
                       " to Slurm: one job per task, the refinement chunks as one job array,\n"
                       "# each waiting for what it reads (--dependency=afterok). Memory per task: measured by a\n"
                       "# finished run-plan of this plan (x 1.5) or the default.\nset -euo pipefail\ncd \"" +
                       slurm.string() + "\"\n";
  std::map<std::string, std::string> job_of;  // task id → shell variable of its job
  int refine_count = 0, refine_memory = 0;
  std::vector<std::string> refine_dependencies;
  for (const nlohmann::json& task : plan.at("tasks")) {
    const std::string id = task.at("id").get<std::string>();
    std::vector<std::string> after;
    for (const auto& dependency : task.at("depends_on")) after.push_back("${" + job_of.at(dependency.get<std::string>()) + "}");
    const int memory = TaskMemoryMiB(directory, task, memory_mib);
    if (task.at("stage") == "refine" && id.rfind("refine_", 0) == 0 && id != "refine_merge") {
      ++refine_count;
      refine_memory = std::max(refine_memory, memory);
      refine_dependencies = after;
      job_of[id] = JobVariable("refine_array");
      continue;
    }
    if (refine_count > 0 && !job_of.count("refine_array_submitted")) {
      std::string dependency;
      for (const std::string& job : refine_dependencies) dependency += ":" + job;
      submit += JobVariable("refine_array") + "=$(sbatch --parsable --job-name=subflow_refine --array=0-" +
                std::to_string(refine_count - 1) + " --mem=" + std::to_string(refine_memory) + "M" +
                (dependency.empty() ? "" : " --dependency=afterok" + dependency) + " refine_array.sbatch)\n";
      job_of["refine_array_submitted"] = "";
    }
    std::string dependency;
    for (const std::string& job : after)
      if (dependency.find(job) == std::string::npos) dependency += ":" + job;
    submit += JobVariable(id) + "=$(sbatch --parsable --job-name=subflow_" + id + " --mem=" + std::to_string(memory) +
              "M" + (dependency.empty() ? "" : " --dependency=afterok" + dependency) + " task.sbatch " + id + ")\n";
    job_of[id] = JobVariable(id);
  }
  submit += "echo \"submitted; the result will be in " + plan.value("result", std::string()) + "; last job ${" +
            JobVariable("split") + "}\"\necho \"${" + JobVariable("split") + "}\" > \"" + (slurm / "last_job").string() +
            "\"\n";
  WriteText(slurm / "submit.sh", submit, true);
}

}  // namespace subflow::output
