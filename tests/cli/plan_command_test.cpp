// `subflow plan` + `subflow run-plan` (output/plan.h, docs/cluster.md) on a 12-frame
// synthetic take in 3 chunks: the plan's tasks and dependencies, the chained motion
// chunks that continue each other's trajectories (vertex i is one material point across
// chunk boundaries), the merged result against the single-process `reconstruct`, a killed
// task re-run alone giving the same result, the sbatch scripts, and planning again into
// a plan's folder (task stamps: only what a changed option defines runs again).
#include <filesystem>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "geometry/mesh_io.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;
using test::RunSubflow;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("plan_command");
  return scratch;
}
std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// A small deforming blob: 6 gray cameras, 12 frames, 160×120.
const fs::path& Dataset() {
  static const fs::path dataset = [] {
    const fs::path path = Scratch() / "blob";
    const test::CommandResult run = RunSubflow("synth blob --out " + Quoted(path) +
                                                   " --cameras 6 --frames 12 --width 160 --height 120 "
                                                   "--subdivisions 4 --gray",
                                               Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return path;
  }();
  return dataset;
}
const std::string kOptions = " --base-faces 120 --levels 2 --window 3 --iterations 4 ";

test::CommandResult RunOk(const std::string& arguments) {
  const test::CommandResult run = RunSubflow(arguments, Scratch().path());
  EXPECT_EQ(run.exit_code, 0) << arguments << "\n" << run.output();
  return run;
}
nlohmann::json ReadJson(const fs::path& path) { return nlohmann::json::parse(test::ReadTextFile(path)); }

const fs::path& PlanDirectory() {
  static const fs::path directory = [] {
    const fs::path path = Scratch().FreshPath("plan");
    RunOk("plan " + Quoted(Dataset()) + " --out " + Quoted(path) + " --chunk 4 --overlap 1 --slurm" + kOptions);
    RunOk("run-plan " + Quoted(path));
    return path;
  }();
  return directory;
}

// eval's JSON of `result`.
nlohmann::json Evaluate(const fs::path& result, const std::string& name) {
  const fs::path json = Scratch() / (name + "_eval.json");
  RunOk("eval " + Quoted(Dataset()) + " " + Quoted(result) + " --overwrite --json " + Quoted(json));
  return ReadJson(json);
}

geometry::Positions Control(const fs::path& folder, const char* frame) {
  return geometry::ReadMesh((folder / "control" / frame / "level_2.ply").string()).V;
}

void AKilledTaskRerunsAloneAndGivesTheSameResult();
void SlurmScriptsUseAnArrayAndAfterokDependencies();

TEST(PlanCommand, ThePlanRunsChainedChunksAndRestarts) {
  const nlohmann::json plan = ReadJson(PlanDirectory() / "plan.json");
  EXPECT_EQ(plan["chunks"], 3);
  EXPECT_EQ(plan["reference_frame"], 6);
  std::map<std::string, nlohmann::json> tasks;
  for (const auto& task : plan["tasks"]) tasks[task["id"]] = task;
  EXPECT_EQ(tasks.size(), 14u);  // shape, 3 × (motion, refine, retrack), 3 merges, split
  EXPECT_EQ(tasks["motion_1"]["frames"], (nlohmann::json{4, 8}));  // the reference chunk
  EXPECT_EQ(tasks["motion_2"]["frames"], (nlohmann::json{7, 12}));  // from motion_1's frame 7
  EXPECT_EQ(tasks["motion_0"]["frames"], (nlohmann::json{0, 5}));   // from motion_1's frame 4
  EXPECT_EQ(tasks["motion_2"]["depends_on"], (nlohmann::json{"shape", "motion_1"}));
  EXPECT_EQ(tasks["refine_0"]["frames"], (nlohmann::json{0, 5}));  // widened by the overlap
  EXPECT_EQ(tasks["refine_1"]["frames"], (nlohmann::json{3, 9}));
  EXPECT_EQ(tasks["split"]["depends_on"], (nlohmann::json{"retrack_merge"}));

  // The seeded chunk starts where the one before it is: the same control points at the
  // shared frame, so no vertex jumps at the boundary.
  const fs::path dir = PlanDirectory();
  EXPECT_EQ(ReadJson(dir / "motion_2" / "report.json")["seed"]["frame"], 7);
  // …and its first step is offered motion_1's velocity at that frame (its control points
  // at 6 and 7) as its previous step, as the next step of one chain is offered its previous
  // one; motion_0 continues motion_1 backwards from frame 4 (with frame 5). motion_1's own
  // first steps, from the reference frame 6, are offered nothing.
  auto offered = [&](const char* task, int frame) {
    const nlohmann::json report = ReadJson(dir / task / "report.json");  // named: the loop reads into it
    for (const auto& f : report["motion_init"]["frames"])
      if (f["frame"] == frame) return f.contains("guess") ? f["guess"]["offered"] : nlohmann::json::array();
    ADD_FAILURE() << task << " has no frame " << frame;
    return nlohmann::json();
  };
  EXPECT_EQ(ReadJson(dir / "motion_2" / "report.json")["seed"]["lead_in_frame"], 6);
  EXPECT_EQ(ReadJson(dir / "motion_0" / "report.json")["seed"]["lead_in_frame"], 5);
  EXPECT_EQ(offered("motion_2", 8), nlohmann::json::array({"previous_step"}));
  EXPECT_EQ(offered("motion_0", 3), nlohmann::json::array({"previous_step"}));
  EXPECT_EQ(offered("motion_1", 7), nlohmann::json::array());
  EXPECT_EQ(offered("motion_1", 5), nlohmann::json::array());
  EXPECT_EQ(offered("motion_1", 4), nlohmann::json::array({"previous_step"}));  // its second step backwards
  EXPECT_EQ(Control(dir / "motion_2", "000007"), Control(dir / "motion_1", "000007"));
  EXPECT_EQ(Control(dir / "motion_0", "000004"), Control(dir / "motion_1", "000004"));
  EXPECT_EQ(Control(dir / "retrack_2", "000007"), Control(dir / "retrack_1", "000007"));
  EXPECT_EQ(ReadJson(dir / "status" / "refine_1.json")["exit_code"], 0);
  EXPECT_GT(ReadJson(dir / "status" / "refine_1.json")["max_rss_kib"].get<double>(), 0.0);
  SlurmScriptsUseAnArrayAndAfterokDependencies();
  AKilledTaskRerunsAloneAndGivesTheSameResult();
}

TEST(PlanCommand, TheMergedResultMatchesTheSingleProcessRun) {
  const fs::path single = Scratch().FreshPath("single");
  RunOk("reconstruct " + Quoted(Dataset()) + " --out " + Quoted(single) + kOptions);
  const nlohmann::json a = Evaluate(single, "single"), b = Evaluate(PlanDirectory() / "result", "plan");
  const double accuracy = a["overall"]["observed"]["accuracy"], plan_accuracy = b["overall"]["observed"]["accuracy"];
  const double epe = a["overall"]["observed"]["flow"]["epe_mean"], plan_epe = b["overall"]["observed"]["flow"]["epe_mean"];
  std::cout << "accuracy " << accuracy << " → " << plan_accuracy << ", EPE " << epe << " → " << plan_epe << "\n";
  EXPECT_LE(plan_accuracy, 1.05 * accuracy);
  EXPECT_LE(plan_epe, 1.05 * epe);
  // No seam: the flow of the frame steps across chunk boundaries (3→4, 7→8) is no worse
  // than 1.5 × the mean of the others.
  double boundary = 0, elsewhere = 0;
  int others = 0;
  for (const auto& frame : b["frames"]) {
    if (!frame.contains("flow") || frame["flow"].is_null()) continue;
    const int f = frame["frame"];
    const double value = frame["observed"]["flow"]["epe_mean"];
    if (f == 3 || f == 7)
      boundary = std::max(boundary, value);
    else
      elsewhere += value, ++others;
  }
  ASSERT_GT(others, 0);
  std::cout << "seam EPE " << boundary << ", elsewhere " << elsewhere / others << "\n";
  EXPECT_LE(boundary, 1.5 * elsewhere / others);
}

// (Part of PlanCommand.ThePlanRunsChainedChunksAndRestarts: one run-plan per process.)
void AKilledTaskRerunsAloneAndGivesTheSameResult() {
  const fs::path dir = PlanDirectory();
  const auto mesh = [&](const char* frame) {
    return geometry::ReadMesh((dir / "result" / "meshes" / (std::string(frame) + ".ply")).string()).V;
  };
  std::vector<geometry::Positions> before;
  for (const char* frame : {"000000", "000005", "000011"}) before.push_back(mesh(frame));
  // refine_1 killed while writing (its files are there, its report.json is not), so
  // nothing after it ran.
  for (const char* task : {"refine_1", "refine_merge", "retrack_0", "retrack_1", "retrack_2", "retrack_merge", "result"})
    fs::remove(dir / task / "report.json");
  const test::CommandResult run = RunOk("run-plan " + Quoted(dir));
  for (const char* task : {"shape", "motion_0", "motion_merge", "refine_0", "refine_2"})
    EXPECT_NE(run.output().find(std::string("run-plan: ") + task + " finished already (skipped)"), std::string::npos)
        << task << "\n" << run.output();
  EXPECT_NE(run.output().find("run-plan: refine_1 ("), std::string::npos) << run.output();
  int i = 0;
  for (const char* frame : {"000000", "000005", "000011"}) EXPECT_EQ(mesh(frame), before[i++]) << frame;
}

// The ids of the tasks a run-plan ran (not those it skipped as finished), from its log.
std::set<std::string> TasksRun(const test::CommandResult& run, const nlohmann::json& plan) {
  std::set<std::string> ran;
  for (const auto& task : plan["tasks"])
    if (run.output().find("run-plan: " + task["id"].get<std::string>() + " (") != std::string::npos)
      ran.insert(task["id"].get<std::string>());
  return ran;
}

// Planning again into a plan's folder: the same options change nothing (no task runs
// again); another refinement option is refused without --overwrite, naming the folder and
// the tasks it changes, and with --overwrite exactly the refinement tasks and those
// downstream of them run again, the shape and motion tasks' results are kept.
TEST(PlanCommand, PlanningAgainRerunsExactlyTheTasksItChanges) {
  const fs::path dir = Scratch().FreshPath("replan");
  const std::string plan = "plan " + Quoted(Dataset()) + " --out " + Quoted(dir) + " --frames 0:8 --chunk 4 --overlap 1";
  RunOk(plan + kOptions);
  const nlohmann::json first = ReadJson(dir / "plan.json");
  EXPECT_EQ(TasksRun(RunOk("run-plan " + Quoted(dir)), first).size(), first["tasks"].size());

  RunOk(plan + kOptions);  // the same plan: allowed without --overwrite, and nothing to do
  EXPECT_EQ(ReadJson(dir / "plan.json")["tasks"], first["tasks"]);
  const test::CommandResult again = RunOk("run-plan " + Quoted(dir));
  EXPECT_TRUE(TasksRun(again, first).empty()) << again.output();

  const std::string changed = " --base-faces 120 --levels 2 --window 3 --iterations 3 ";  // refinement's
  const test::CommandResult refused = RunSubflow(plan + changed, Scratch().path());
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output().find(dir.string()), std::string::npos) << refused.output();
  EXPECT_NE(refused.output().find("differs from this one (tasks defined otherwise: refine_0, refine_1, refine_merge"),
            std::string::npos)
      << refused.output();
  EXPECT_NE(refused.output().find("--overwrite"), std::string::npos) << refused.output();
  EXPECT_EQ(ReadJson(dir / "plan.json")["tasks"], first["tasks"]);  // untouched

  RunOk(plan + changed + "--overwrite");
  const nlohmann::json second = ReadJson(dir / "plan.json");
  const test::CommandResult rerun = RunOk("run-plan " + Quoted(dir));
  const std::set<std::string> expected = {"refine_0", "refine_1", "refine_merge", "retrack_0",
                                          "retrack_1", "retrack_merge", "split"};
  EXPECT_EQ(TasksRun(rerun, second), expected) << rerun.output();
  EXPECT_EQ(ReadJson(dir / "refine_0" / "report.json")["options"]["refinement"]["solver"]["max_iterations"], 3);
  EXPECT_EQ(ReadJson(dir / "result" / "report.json")["options"]["refinement"]["solver"]["max_iterations"], 3);
  EXPECT_TRUE(TasksRun(RunOk("run-plan " + Quoted(dir)), second).empty());
}

void SlurmScriptsUseAnArrayAndAfterokDependencies() {
  const std::string submit = test::ReadTextFile(PlanDirectory() / "slurm" / "submit.sh");
  EXPECT_NE(submit.find("--array=0-2"), std::string::npos) << submit;
  EXPECT_NE(submit.find("--dependency=afterok:${job_shape}"), std::string::npos) << submit;
  EXPECT_NE(submit.find("task.sbatch split"), std::string::npos) << submit;
  EXPECT_NE(test::ReadTextFile(PlanDirectory() / "slurm" / "refine_array.sbatch").find("SLURM_ARRAY_TASK_ID"),
            std::string::npos);
}

}  // namespace
}  // namespace subflow
