// report.json sections of `subflow reconstruct`: motion initialization, stereo refinement,
// rigid motion per frame step, per-stage timings.
#pragma once

#include <nlohmann/json.hpp>

#include "solver/reconstruction.h"

namespace subflow::cli {

nlohmann::json MotionInitJson(const solver::MotionInitOptions& options, const solver::MotionInitResult& result,
                              int first_frame);
nlohmann::json RefinementJson(const solver::StereoRefinementOptions& options,
                              const solver::RefinementResult& result, int first_frame);
nlohmann::json RigidMotionJson(const std::vector<solver::RigidMotion>& rigid, int first_frame);

}  // namespace subflow::cli
