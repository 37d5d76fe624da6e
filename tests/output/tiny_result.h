// A tiny result folder in the OUTPUT.md layout, written in the test: an icosphere whose
// vertices move by a known motion per frame (a translation and a travelling wave along
// the radius), so exports can be compared with the exact positions.
#pragma once

#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "geometry/icosphere.h"
#include "output/result_writer.h"

namespace subflow::test {

struct TinyResultOptions {
  int frames = 5;
  int subdivisions = 2;           // 162 vertices, 320 faces
  double fps = 25.0;              // recorded as report.json's dataset.fps; ≤ 0: absent
  bool static_half = false;       // vertices with z < 0 never move (sparse morph targets)
};

// Positions of frame f of the tiny result.
inline geometry::Positions TinyResultPositions(const geometry::TriangleMesh& sphere, int f,
                                               const TinyResultOptions& options) {
  geometry::Positions V = sphere.V;
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    if (options.static_half && sphere.V(v, 2) < 0.0) continue;
    const Eigen::RowVector3d rest = sphere.V.row(v);
    const double wave = 0.01 * std::sin(12.0 * rest.x() + 0.7 * f);
    V.row(v) = rest * (1.0 + wave) + f * Eigen::RowVector3d(0.0013, -0.0007, 0.0004);
  }
  return V;
}

// Writes <directory>/meshes/<frame>.ply (x y z, vx vy vz, nonrigid_v*) and report.json.
inline void WriteTinyResult(const std::filesystem::path& directory, const TinyResultOptions& options = {}) {
  const geometry::TriangleMesh sphere = geometry::MakeIcosphere(options.subdivisions, 0.1);
  std::vector<geometry::Positions> positions;
  for (int f = 0; f < options.frames; ++f) positions.push_back(TinyResultPositions(sphere, f, options));
  std::map<std::string, std::vector<Eigen::VectorXd>> properties;
  for (int f = 0; f < options.frames; ++f) {
    // Non-rigid part: the motion minus the translation (the wave's share).
    const Eigen::RowVector3d translation = options.static_half || f + 1 == options.frames
                                               ? Eigen::RowVector3d::Zero()
                                               : Eigen::RowVector3d(0.0013, -0.0007, 0.0004);
    const geometry::Positions motion =
        f + 1 < options.frames ? geometry::Positions(positions[f + 1] - positions[f])
                               : geometry::Positions(geometry::Positions::Zero(sphere.V.rows(), 3));
    const char* axes[3] = {"nonrigid_vx", "nonrigid_vy", "nonrigid_vz"};
    for (int axis = 0; axis < 3; ++axis)
      properties[axes[axis]].push_back((motion.col(axis).array() - translation[axis]).matrix());
  }
  output::WriteResultMeshes(directory.string(), 0, sphere.F, positions, properties);
  nlohmann::json dataset = {{"units", "meters"}};
  if (options.fps > 0) dataset["fps"] = options.fps;
  output::WriteJsonFile((directory / "report.json").string(), {{"command", "test"}, {"dataset", dataset}});
}

}  // namespace subflow::test
