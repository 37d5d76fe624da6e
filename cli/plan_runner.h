// Running a plan's tasks (output/plan.h) here, each as a child process of this binary:
// `subflow run-plan` and the chunked `subflow reconstruct` (a take longer than --chunk).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace subflow::cli {

// Runs every task of `plan` (read from `directory`) in order, or only the task `only`
// when not empty, skipping the finished ones (output::TaskFinished). Each run records
// directory/status/<id>.json: exit code, seconds and peak resident memory (max_rss_kib).
// SIGINT / SIGTERM to this process are passed on to the running task, which stops at its
// next progress point; then subflow::Interrupted is thrown (core/interrupt.h). A failed
// task throws subflow::Error naming plan.json and the task. Returns, per task run or
// skipped: {"id", "stage", "frames", "skipped", "seconds", "max_rss_kib"}.
nlohmann::json RunPlanTasks(const std::string& directory, const nlohmann::json& plan, const std::string& only = "");

}  // namespace subflow::cli
