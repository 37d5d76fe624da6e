// report.json records every field of every options struct (output/options_json.h): the
// number of keys written equals the number of fields of the struct, counted by the
// largest brace initializer the aggregate accepts, so a field added to a struct without
// adding it to the report fails here. Recorded options read back to the same values.
#include <cstddef>
#include <utility>

#include <gtest/gtest.h>

#include "output/options_json.h"

namespace subflow::output {
namespace {

// Converts to anything: one initializer of any field.
struct AnyField {
  template <typename T>
  constexpr operator T() const;  // declared only: used in unevaluated contexts
};

template <typename T, typename... Fields>
constexpr auto BraceInitializable(int) -> decltype(T{std::declval<Fields>()...}, true) {
  return true;
}
template <typename T, typename... Fields>
constexpr bool BraceInitializable(...) {
  return false;
}
template <typename T, std::size_t... I>
constexpr bool InitializableWith(std::index_sequence<I...>) {
  return BraceInitializable<T, decltype((void)I, AnyField{})...>(0);
}
// The number of fields of the aggregate T (nested aggregates count as one field).
template <typename T, std::size_t N = 0>
constexpr std::size_t FieldCount() {
  if constexpr (InitializableWith<T>(std::make_index_sequence<N + 1>{}))
    return FieldCount<T, N + 1>();
  else
    return N;
}

struct Three {
  int a = 0;
  std::vector<double> b;
  vision::SilhouetteOptions c;
};
static_assert(FieldCount<Three>() == 3, "the field counter counts nested aggregates once");

template <typename Options>
void ExpectEveryFieldRecorded(const char* name) {
  const nlohmann::json json = Options{};
  EXPECT_TRUE(json.is_object()) << name;
  EXPECT_EQ(json.size(), FieldCount<Options>()) << name << ": " << json.dump();
  // Read back: the same record.
  EXPECT_EQ(nlohmann::json(json.get<Options>()), json) << name;
}

TEST(OptionsJson, EveryFieldOfEveryOptionsStructIsRecordedAndReadsBack) {
  ExpectEveryFieldRecorded<vision::SilhouetteOptions>("SilhouetteOptions");
  ExpectEveryFieldRecorded<vision::VoxelCarvingOptions>("VoxelCarvingOptions");
  ExpectEveryFieldRecorded<vision::StandingEvidenceOptions>("StandingEvidenceOptions");
  ExpectEveryFieldRecorded<vision::PlaneSweepOptions>("PlaneSweepOptions");
  ExpectEveryFieldRecorded<vision::DepthFusionOptions>("DepthFusionOptions");
  ExpectEveryFieldRecorded<vision::SupportPlaneOptions>("SupportPlaneOptions");
  ExpectEveryFieldRecorded<vision::PlainBackdropOptions>("PlainBackdropOptions");
  ExpectEveryFieldRecorded<vision::StillEvidenceOptions>("StillEvidenceOptions");
  ExpectEveryFieldRecorded<geometry::IsosurfaceOptions>("IsosurfaceOptions");
  ExpectEveryFieldRecorded<geometry::SimplifyOptions>("SimplifyOptions");
  ExpectEveryFieldRecorded<solver::HierarchyFitOptions>("HierarchyFitOptions");
  ExpectEveryFieldRecorded<solver::SurfaceRegistrationOptions>("SurfaceRegistrationOptions");
  ExpectEveryFieldRecorded<solver::ShapeInitOptions>("ShapeInitOptions");
  ExpectEveryFieldRecorded<solver::SurfaceSamplingOptions>("SurfaceSamplingOptions");
  ExpectEveryFieldRecorded<solver::VisibilityOptions>("VisibilityOptions");
  ExpectEveryFieldRecorded<solver::NormalFlowSolverOptions>("NormalFlowSolverOptions");
  ExpectEveryFieldRecorded<solver::MotionStepOptions>("MotionStepOptions");
  ExpectEveryFieldRecorded<solver::MotionInitOptions>("MotionInitOptions");
  ExpectEveryFieldRecorded<solver::WindowSolverOptions>("WindowSolverOptions");
  ExpectEveryFieldRecorded<solver::StereoRefinementOptions>("StereoRefinementOptions");
  ExpectEveryFieldRecorded<solver::ReconstructionOptions>("ReconstructionOptions");
}

TEST(OptionsJson, EnumsAreRecordedByTheirCommandLineNames) {
  solver::ReconstructionOptions options;
  options.shape.silhouettes.source = vision::EvidenceSource::kBackground;
  options.refinement.solver.linear_solver = ceres::ITERATIVE_SCHUR;
  const nlohmann::json json = options;
  EXPECT_EQ(json.at("shape_init").at("silhouettes").at("source"), "background");
  EXPECT_EQ(json.at("shape_init").at("silhouettes").at("background_method"), "triangle");
  EXPECT_EQ(json.at("refinement").at("solver").at("linear_solver"), "iterative_schur");
  nlohmann::json bad = json;
  bad["refinement"]["solver"]["linear_solver"] = "magic";
  EXPECT_THROW(bad.get<solver::ReconstructionOptions>(), Error);
  bad = json;
  bad["shape_init"]["silhouettes"]["motion_method"] = "median";
  EXPECT_THROW(bad.get<solver::ReconstructionOptions>(), Error);
}

// An options file written before the retrack had its own high-pass (no "retrack_highpass")
// runs its retrack as it ran then: on the first motion pass's high-pass.
TEST(OptionsJson, AnOlderFileKeepsItsRetrackOnTheFirstPasssHighPass) {
  solver::ReconstructionOptions options;
  options.motion.step.highpass_sigma = 1.5;
  nlohmann::json json = options;
  ASSERT_NE(options.retrack_highpass, 1.5);
  EXPECT_EQ(json.get<solver::ReconstructionOptions>().retrack_highpass, options.retrack_highpass);
  json.erase("retrack_highpass");
  const solver::ReconstructionOptions older = json.get<solver::ReconstructionOptions>();
  EXPECT_EQ(older.retrack_highpass, 1.5);
  EXPECT_EQ(older.RetrackOptions().step.highpass_sigma, 1.5);
}

// An options file written before the plain backdrop (no "backdrop" in shape_init.still)
// reads with the backdrop's defaults; the backdrop's own fields round-trip.
TEST(OptionsJson, AnOlderFileWithoutTheBackdropTakesItsDefaults) {
  solver::ReconstructionOptions options;
  options.shape.still.backdrop.max_spread = 0.05;
  options.shape.still.backdrop.enabled = false;
  nlohmann::json json = options;
  const solver::ReconstructionOptions read = json.get<solver::ReconstructionOptions>();
  EXPECT_EQ(read.shape.still.backdrop.max_spread, 0.05);
  EXPECT_FALSE(read.shape.still.backdrop.enabled);
  json["shape_init"]["still"].erase("backdrop");
  const solver::ReconstructionOptions older = json.get<solver::ReconstructionOptions>();
  EXPECT_EQ(older.shape.still.backdrop.max_spread, vision::PlainBackdropOptions().max_spread);
  EXPECT_TRUE(older.shape.still.backdrop.enabled);
}

// The motion passes try the previous step as a start since 2026-12-07: an options file
// written before has no guess_previous_step and reads as off, as its runs did.
TEST(OptionsJson, AnOlderFileKeepsItsStepsWithoutTheVelocityGuess) {
  solver::ReconstructionOptions options;
  ASSERT_TRUE(options.motion.guess_previous_step);
  nlohmann::json json = options;
  EXPECT_TRUE(json.get<solver::ReconstructionOptions>().motion.guess_previous_step);
  json["motion_init"].erase("guess_previous_step");
  const solver::ReconstructionOptions older = json.get<solver::ReconstructionOptions>();
  EXPECT_FALSE(older.motion.guess_previous_step);
  EXPECT_FALSE(older.RetrackOptions().guess_previous_step);
}

// concurrent_halves was a bool before it had an automatic mode: an older file's true / false
// reads as "on" / "off" (what those runs did), the mode's names round-trip, others fail.
TEST(OptionsJson, ConcurrentHalvesReadsTheOlderBoolAndTheModesNames) {
  nlohmann::json json = solver::ReconstructionOptions();
  EXPECT_EQ(json.at("refinement").at("concurrent_halves"), "auto");
  EXPECT_EQ(json.get<solver::ReconstructionOptions>().refinement.concurrent_halves, solver::ConcurrentHalves::kAuto);
  json["refinement"]["concurrent_halves"] = true;
  EXPECT_EQ(json.get<solver::ReconstructionOptions>().refinement.concurrent_halves, solver::ConcurrentHalves::kOn);
  json["refinement"]["concurrent_halves"] = false;
  EXPECT_EQ(json.get<solver::ReconstructionOptions>().refinement.concurrent_halves, solver::ConcurrentHalves::kOff);
  json["refinement"]["concurrent_halves"] = "on";
  EXPECT_EQ(json.get<solver::ReconstructionOptions>().refinement.concurrent_halves, solver::ConcurrentHalves::kOn);
  json["refinement"]["concurrent_halves"] = "sometimes";
  EXPECT_THROW(json.get<solver::ReconstructionOptions>(), Error);
}

// The sliding vertices are tied over the frames since 2026-12-08: an options file written
// before has no slide_coherence and reads as 0, as its runs did.
TEST(OptionsJson, AnOlderFileHasNoSlideCoherence) {
  solver::ReconstructionOptions options;
  ASSERT_GT(options.refinement.slide_coherence, 0.0);
  options.refinement.slide_coherence = 2.5;
  nlohmann::json json = options;
  EXPECT_EQ(json.get<solver::ReconstructionOptions>().refinement.slide_coherence, 2.5);
  json["refinement"].erase("slide_coherence");
  EXPECT_EQ(json.get<solver::ReconstructionOptions>().refinement.slide_coherence, 0.0);
}

}  // namespace
}  // namespace subflow::output
