// Task stamps and re-planning (declared in output/plan.h, docs/cluster.md "Planning
// again"): what defines each task's output, recorded in plan.json and beside the output,
// so that a task is finished only for the plan it was run for.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <vector>

#include "core/error.h"
#include "core/json_reader.h"
#include "output/plan.h"
#include "output/result_writer.h"

namespace subflow::output {

namespace fs = std::filesystem;

namespace {

// 64-bit FNV-1a of `text` as 16 hex digits: a fingerprint, not a security measure (a
// plan's folders are the user's own; what matters is that any change of the definition
// changes it, which 64 bits make certain in practice).
std::string Fingerprint(const std::string& text) {
  std::uint64_t hash = 14695981039346656037ull;
  for (const unsigned char byte : text) {
    hash ^= byte;
    hash *= 1099511628211ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(hash));
  return hex;
}

fs::path StampPath(const nlohmann::json& task) { return fs::path(task.at("output").get<std::string>()) / kTaskStampFile; }

// The stamp recorded in the output folder of `task` ("" when there is none or it is unreadable).
std::string RecordedStamp(const nlohmann::json& task) {
  std::error_code error;
  if (!fs::is_regular_file(StampPath(task), error)) return "";
  try {
    return ReadJsonFile(StampPath(task).string(), "a task stamp (subflow run-plan)").value("stamp", std::string());
  } catch (const std::exception&) {
    return "";  // a damaged stamp: the task runs again
  }
}

// {task id: stamp} of a plan's tasks.
std::map<std::string, std::string> StampsOf(const nlohmann::json& plan) {
  std::map<std::string, std::string> stamps;
  for (const nlohmann::json& task : plan.at("tasks")) stamps[task.at("id")] = task.value("stamp", std::string());
  return stamps;
}

// "a, b, c" (the first kShown ids, then how many more: a long take has hundreds of tasks).
std::string Listed(const std::vector<std::string>& ids) {
  constexpr std::size_t kShown = 8;
  std::string text;
  for (std::size_t i = 0; i < ids.size() && i < kShown; ++i) text += (i == 0 ? "" : ", ") + ids[i];
  if (ids.size() > kShown) text += " and " + std::to_string(ids.size() - kShown) + " more";
  return text;
}

}  // namespace

void StampTasks(nlohmann::json* tasks, const std::vector<nlohmann::json>& options_read, const nlohmann::json& dataset) {
  if (options_read.size() != tasks->size()) ThrowError("plan", "tasks", "one options entry per task expected");
  std::map<std::string, std::string> stamps;
  for (std::size_t i = 0; i < tasks->size(); ++i) {
    nlohmann::json& task = (*tasks)[i];
    nlohmann::json inputs = nlohmann::json::object();
    for (const auto& dependency : task.at("depends_on")) {
      const std::string id = dependency.get<std::string>();
      // Tasks come after those they depend on (the plan runs them in this order).
      if (!stamps.count(id)) ThrowError("plan", "task " + task.at("id").get<std::string>(), "depends on a later task " + id);
      inputs[id] = stamps.at(id);
    }
    const nlohmann::json definition = {{"argv", task.at("argv")},
                                       {"options", options_read[i]},
                                       {"dataset", dataset},
                                       {"depends_on", inputs}};
    // dump() of nlohmann::json sorts object keys: the same definition, the same text.
    task["stamp"] = Fingerprint(definition.dump());
    stamps[task.at("id")] = task["stamp"];
  }
}

bool TaskFinished(const nlohmann::json& task) {
  std::error_code error;
  if (!fs::is_regular_file(fs::path(task.at("output").get<std::string>()) / "report.json", error)) return false;
  const std::string stamp = task.value("stamp", std::string());
  return !stamp.empty() && RecordedStamp(task) == stamp;
}

void ForgetTaskFinished(const nlohmann::json& task) {
  std::error_code error;
  fs::remove(StampPath(task), error);
  if (error) ThrowError(StampPath(task).string(), "", "cannot remove: " + error.message());
}

void RecordTaskFinished(const nlohmann::json& task) {
  WriteJsonFile(StampPath(task).string(), {{"id", task.at("id")}, {"stamp", task.at("stamp")}});
}

void CheckReplan(const std::string& directory, const nlohmann::json& plan, bool overwrite) {
  const fs::path path = fs::path(directory) / "plan.json";
  std::error_code error;
  if (!fs::exists(path, error)) return;
  std::map<std::string, std::string> before;
  std::string why;
  try {
    before = StampsOf(ReadPlan(directory));
  } catch (const std::exception& e) {
    why = std::string("its plan.json cannot be read as this subflow's plan (") + e.what() + ")";
  }
  const std::map<std::string, std::string> now = StampsOf(plan);
  std::vector<std::string> changed, removed, added;
  for (const auto& [id, stamp] : now) {
    if (!before.count(id)) added.push_back(id);
    else if (before.at(id) != stamp) changed.push_back(id);
  }
  for (const auto& [id, stamp] : before)
    if (!now.count(id)) removed.push_back(id);
  if (why.empty() && changed.empty() && removed.empty() && added.empty()) return;  // the same plan
  if (overwrite) return;  // the changed tasks' stamps differ from their folders': they run again
  if (why.empty()) {
    why = "it holds a plan that differs from this one (";
    if (!changed.empty()) why += "tasks defined otherwise: " + Listed(changed);
    if (!added.empty()) why += std::string(changed.empty() ? "" : "; ") + "new tasks: " + Listed(added);
    if (!removed.empty())
      why += std::string(changed.empty() && added.empty() ? "" : "; ") + "tasks no longer planned: " + Listed(removed);
    why += ")";
  }
  ThrowError(directory, "--out",
             why + "; refusing to replace it: plan into another folder, or pass --overwrite (the finished tasks "
                   "whose definition is unchanged are kept, the others run again)");
}

}  // namespace subflow::output
