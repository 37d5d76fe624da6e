#include "output/plan.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/json_reader.h"
#include "output/options_json.h"
#include "output/report.h"
#include "output/result_writer.h"
#include "output/stage_pipeline.h"

namespace subflow::output {

namespace fs = std::filesystem;

void PlanOptions::Check() const {
  if (chunk < 2) ThrowError("plan options", "chunk", "expected at least 2 frames per chunk");
  if (overlap < 0) ThrowError("plan options", "overlap", "expected ≥ 0");
  if (memory_mib < 0) ThrowError("plan options", "memory_mib", "expected ≥ 0 (0 = measured or default)");
}

namespace {

struct Range {
  int first = 0, end = 0;  // dataset frames [first, end)
  std::string Text() const { return std::to_string(first) + ":" + std::to_string(end); }
};

class PlanBuilder {
 public:
  PlanBuilder(std::string dataset, std::string directory, const solver::ReconstructionOptions& options)
      : dataset_(std::move(dataset)), directory_(std::move(directory)), options_(options) {}

  std::string Folder(const std::string& name) const { return (fs::path(directory_) / name).string(); }

  // Adds a task running `arguments` (after the subcommand DATASET, when `with_dataset`).
  void Add(const std::string& id, const std::string& stage, Range frames, std::vector<std::string> arguments,
           const std::vector<std::string>& inputs, const std::string& output, std::vector<std::string> depends_on,
           nlohmann::json options_read = nullptr) {
    options_read_.push_back(std::move(options_read));
    nlohmann::json argv = nlohmann::json::array();
    for (std::string& argument : arguments) argv.push_back(std::move(argument));
    tasks_.push_back({{"id", id},
                      {"stage", stage},
                      {"frames", {frames.first, frames.end}},
                      {"argv", argv},
                      {"inputs", inputs},
                      {"output", output},
                      {"depends_on", depends_on}});
  }

  // A stage command on `from` over `frames` (seeded from `seed` when not empty).
  void AddStage(const std::string& id, const std::string& stage, Range frames, const std::string& from,
                const std::string& seed, const std::vector<std::string>& depends_on) {
    std::vector<std::string> arguments = {stage, dataset_, "--from", from, "--frames", frames.Text(),
                                          "--out", Folder(id), "--overwrite", "--options", Folder("options.json")};
    std::vector<std::string> inputs = {from};
    if (!seed.empty()) {
      arguments.insert(arguments.end(), {"--seed", seed});
      inputs.push_back(seed);
    }
    Add(id, stage, frames, arguments, inputs, Folder(id), depends_on, StageOptionsRead(stage));
  }

  // What a stage task reads of options.json: as its stage report records it.
  nlohmann::json StageOptionsRead(const std::string& stage) const {
    return StageOptionsJson(options_, StageNamed(stage, "plan"));
  }

  // Chained chunks of a motion pass (motion or retrack) on `from`; returns their ids.
  std::vector<std::string> AddChain(const std::string& stage, const std::vector<Range>& chunks, int reference_chunk,
                                    const std::string& from, const std::string& after) {
    std::vector<std::string> ids(chunks.size());
    for (std::size_t c = 0; c < chunks.size(); ++c) ids[c] = stage + "_" + std::to_string(c);
    const auto add = [&](int c, int seed) {
      Range range = chunks[c];
      if (seed >= 0 && seed < c) range.first -= 1;  // starts at the last frame of the chunk before
      if (seed > c) range.end += 1;                 // ends at the first frame of the chunk after
      std::vector<std::string> depends_on = {after};
      if (seed >= 0) depends_on.push_back(ids[seed]);
      AddStage(ids[c], stage, range, from, seed >= 0 ? Folder(ids[seed]) : "", depends_on);
    };
    add(reference_chunk, -1);
    for (int c = reference_chunk + 1; c < static_cast<int>(chunks.size()); ++c) add(c, c - 1);
    for (int c = reference_chunk - 1; c >= 0; --c) add(c, c + 1);
    return ids;
  }

  // `merge` of the folders of `ids` into `id`.
  void AddMerge(const std::string& id, const std::string& stage, Range frames, const std::vector<std::string>& ids) {
    std::vector<std::string> arguments = {"merge"}, inputs;
    for (const std::string& part : ids) arguments.push_back(Folder(part)), inputs.push_back(Folder(part));
    arguments.insert(arguments.end(), {"--out", Folder(id), "--overwrite"});
    Add(id, stage, frames, arguments, inputs, Folder(id), ids);
  }

  // The tasks, each with its stamp (StampTasks).
  nlohmann::json StampedTasks(const nlohmann::json& dataset) {
    StampTasks(&tasks_, options_read_, dataset);
    return tasks_;
  }

 private:
  std::string dataset_, directory_;
  const solver::ReconstructionOptions& options_;
  nlohmann::json tasks_ = nlohmann::json::array();
  std::vector<nlohmann::json> options_read_;  // per task: the options it reads (StampTasks)
};

}  // namespace

std::pair<int, int> TakeFrames(const std::string& dataset_path, const vision::Dataset& dataset,
                               const solver::ShapeInitOptions& options) {
  const int available = dataset.frame_count() - options.first_frame;
  if (available <= 0) ThrowError(dataset_path, "first_frame", "past the last frame");
  return {options.first_frame,
          options.first_frame + (options.frame_count < 0 ? available : std::min(options.frame_count, available))};
}

nlohmann::json WritePlan(const std::string& dataset_directory, const vision::Dataset& dataset,
                         const solver::ReconstructionOptions& options, const PlanOptions& plan_options,
                         const std::string& directory_name, bool overwrite, const nlohmann::json& arguments) {
  options.Check();
  plan_options.Check();
  const std::string directory = fs::absolute(directory_name).lexically_normal().string();
  const std::string dataset_path = fs::absolute(dataset_directory).lexically_normal().string();
  const solver::ShapeInitOptions& shape = options.shape;
  const auto [take_first, take_end] = TakeFrames(dataset_path, dataset, shape);
  const Range take{take_first, take_end};
  const int reference = shape.reference_frame < 0 ? take.first + (take.end - take.first) / 2 : shape.reference_frame;
  // The fewest chunks of at most `chunk` frames, their sizes differing by at most one
  // (101 frames at 100: 51 + 50, not 100 + 1).
  const int frames = take.end - take.first;
  const int count = (frames + plan_options.chunk - 1) / plan_options.chunk;
  std::vector<Range> chunks;
  int reference_chunk = 0;
  for (int c = 0; c < count; ++c) {
    chunks.push_back({take.first + static_cast<int>(static_cast<long long>(c) * frames / count),
                      take.first + static_cast<int>(static_cast<long long>(c + 1) * frames / count)});
    if (reference >= chunks.back().first && reference < chunks.back().end) reference_chunk = c;
  }

  PlanBuilder plan(dataset_path, directory, options);
  plan.Add("shape", "shape", take,
           {"shape", dataset_path, "--out", plan.Folder("shape"), "--overwrite", "--options",
            plan.Folder("options.json")},
           {}, plan.Folder("shape"), {}, plan.StageOptionsRead("shape"));
  std::string last = "motion_merge";
  plan.AddMerge("motion_merge", "motion", take, plan.AddChain("motion", chunks, reference_chunk, plan.Folder("shape"), "shape"));
  if (options.refine) {
    std::vector<std::string> refine_ids;
    for (std::size_t c = 0; c < chunks.size(); ++c) {
      const Range widened{std::max(take.first, chunks[c].first - plan_options.overlap),
                          std::min(take.end, chunks[c].end + plan_options.overlap)};
      refine_ids.push_back("refine_" + std::to_string(c));
      plan.AddStage(refine_ids.back(), "refine", widened, plan.Folder("motion_merge"), "", {"motion_merge"});
    }
    plan.AddMerge("refine_merge", "refine", take, refine_ids);
    last = "refine_merge";
    if (options.retrack) {
      plan.AddMerge("retrack_merge", "retrack", take,
                    plan.AddChain("retrack", chunks, reference_chunk, plan.Folder("refine_merge"), "refine_merge"));
      last = "retrack_merge";
    }
  }
  plan.Add("split", "split", take,
           {"split", dataset_path, "--from", plan.Folder(last), "--out", plan.Folder("result"), "--overwrite"},
           {plan.Folder(last)}, plan.Folder("result"), {last});

  nlohmann::json json = {{"plan_version", kPlanVersion},
                         {"arguments", arguments},
                         {"dataset", dataset_path},
                         {"directory", directory},
                         {"frames", {take.first, take.end}},
                         {"reference_frame", reference},
                         {"chunk", plan_options.chunk},
                         {"overlap", plan_options.overlap},
                         {"chunks", chunks.size()},
                         {"options", "options.json"},
                         {"result", plan.Folder("result")},
                         {"tasks", plan.StampedTasks(DatasetJson(dataset))}};
  CheckReplan(directory, json, overwrite);
  WriteJsonFile((fs::path(directory) / "options.json").string(), nlohmann::json(options));
  WriteJsonFile((fs::path(directory) / "plan.json").string(), json);
  if (plan_options.slurm) WriteSlurmScripts(directory, json, plan_options.memory_mib);
  return json;
}

nlohmann::json ReadPlan(const std::string& directory) {
  const std::string path = (fs::path(directory) / "plan.json").string();
  nlohmann::json plan = ReadJsonFile(path, "a plan (subflow plan)");
  const JsonReader reader(path);
  if (reader.Integer(reader.Required(plan, "plan_version", ""), "plan_version", 0, 1 << 20) != kPlanVersion)
    reader.Fail("plan_version", "expected " + std::to_string(kPlanVersion) +
                                    " (a plan of another subflow version: plan it again with --overwrite)");
  const nlohmann::json& tasks = reader.Required(plan, "tasks", "");
  if (!tasks.is_array() || tasks.empty()) reader.Fail("tasks", "expected a non-empty array");
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const std::string where = "tasks[" + std::to_string(i) + "]";
    for (const char* key : {"id", "output", "stamp"}) reader.String(reader.Required(tasks[i], key, where), where + "." + key);
    for (const char* key : {"argv", "depends_on"})
      if (!reader.Required(tasks[i], key, where).is_array()) reader.Fail(where + "." + key, "expected an array");
  }
  return plan;
}

namespace {

// The report.json key of a plan task's stage in "timings_seconds".
std::string TimingKey(const std::string& stage) {
  if (stage == "shape") return "shape_init";
  if (stage == "motion") return "motion_init";
  if (stage == "refine") return "refinement";
  return stage;  // retrack, split
}

}  // namespace

void AdoptPlanResult(const nlohmann::json& plan, const nlohmann::json& tasks, const std::string& out,
                     nlohmann::json head, double total_seconds) {
  const fs::path result = plan.at("result").get<std::string>();
  const fs::path result_report = result / "report.json";
  nlohmann::json report = ReadJsonFile(result_report.string(), "the report of the plan's split task");
  // The split task is no longer finished before anything leaves its folder: a run stopped
  // while moving makes --resume run it again, not skip it with half its files gone.
  std::error_code error;
  for (const fs::path& file : {result_report, result / kTaskStampFile}) {
    fs::remove(file, error);
    if (error) ThrowError(file.string(), "", "cannot remove: " + error.message());
  }
  for (const char* entry : kResultEntries) {
    const std::string name = entry;
    if (name == "report.json" || name == "stages" || name == "plan" || !fs::exists(result / name)) continue;
    fs::remove_all(fs::path(out) / name, error);
    if (!error) fs::rename(result / name, fs::path(out) / name, error);
    if (error) ThrowError((fs::path(out) / name).string(), "", "cannot move the plan's result here: " + error.message());
  }
  fs::remove_all(result, error);
  if (error) ThrowError(result.string(), "", "cannot remove the plan's emptied result folder: " + error.message());

  nlohmann::json timings = nlohmann::json::object();
  for (const nlohmann::json& task : tasks) {
    const std::string key = TimingKey(task.value("stage", ""));
    timings[key] = timings.value(key, 0.0) + task.value("seconds", 0.0);
  }
  timings["total"] = total_seconds;
  report.update(head);
  report["timings_seconds"] = timings;
  report["total_seconds"] = total_seconds;
  report["plan"] = {{"directory", plan.at("directory")},
                    {"chunk", plan.at("chunk")},
                    {"overlap", plan.at("overlap")},
                    {"chunks", plan.at("chunks")},
                    {"tasks", tasks}};
  WriteJsonFile((fs::path(out) / "report.json").string(), report);
}

}  // namespace subflow::output
