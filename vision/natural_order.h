// Natural order of names ("cam2" < "cam10"): runs of digits compare as numbers, the rest
// character by character — the order Pose2Sim, Anipose and file browsers list cameras
// and frames in.
#pragma once

#include <string>

namespace subflow::vision {

bool NaturalLess(const std::string& a, const std::string& b);

}  // namespace subflow::vision
