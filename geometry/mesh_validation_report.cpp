// Presentation of a MeshValidationReport: text for people, JSON for tools.
#include <cmath>

#include <nlohmann/json.hpp>
#include <spdlog/fmt/fmt.h>

#include "geometry/mesh_validation.h"

namespace subflow::geometry {
namespace {

std::string YesNo(bool value) { return value ? "yes" : "no"; }

std::string CheckLine(const SelfIntersectionResult& check) {
  if (!check.ran) return check.note.empty() ? "not run" : check.note;
  std::string line;
  if (!check.found())
    line = "none";
  else if (check.pair_count >= 0)
    line = fmt::format("{} pairs over {} faces", check.pair_count, check.reported_face_count);
  else
    line = fmt::format("{} faces", check.reported_face_count);
  if (!check.example_pairs.empty()) {
    line += " (e.g.";
    for (size_t i = 0; i < std::min<size_t>(check.example_pairs.size(), 3); ++i)
      line += fmt::format(" {}×{}", check.example_pairs[i].first, check.example_pairs[i].second);
    line += ")";
  }
  line += fmt::format(" [{:.3f} s]", check.seconds);
  if (!check.note.empty()) line += "; " + check.note;
  return line;
}

nlohmann::ordered_json CheckJson(const SelfIntersectionResult& check, int max_examples) {
  nlohmann::ordered_json json;
  json["ran"] = check.ran;
  json["note"] = check.note;
  json["found"] = check.found();
  if (check.pair_count >= 0) json["pair_count"] = check.pair_count;
  json["face_count"] = check.reported_face_count;
  json["example_pairs"] = nlohmann::ordered_json::array();
  for (const auto& [i, j] : check.example_pairs) json["example_pairs"].push_back({i, j});
  json["example_faces"] = nlohmann::ordered_json::array();
  for (size_t k = 0; k < check.intersecting_faces.size() && static_cast<int>(k) < max_examples; ++k)
    json["example_faces"].push_back(check.intersecting_faces[k]);
  json["degenerate_faces"] = check.degenerate_face_count;
  json["seconds"] = check.seconds;
  return json;
}

}  // namespace

std::string MeshValidationReport::FullReport() const {
  std::string text;
  text += fmt::format("elements:   {} vertices, {} faces, {} edges; {} unreferenced vertices\n",
                      vertex_count, face_count, edge_count, unreferenced_vertex_count);
  text += fmt::format("closed:     {} ({} boundary edges in {} loops)\n", YesNo(closed),
                      boundary_edge_count, boundary_loop_count);
  text += fmt::format(
      "manifold:   {} ({} non-manifold edges, {} non-manifold vertices, {} faces repeating a "
      "vertex)\n",
      YesNo(manifold), non_manifold_edge_count, non_manifold_vertex_count,
      repeated_vertex_face_count);
  text += fmt::format("oriented:   {} consistently ({} inconsistent edges); outward: {}\n",
                      consistently_oriented ? "yes," : "not", inconsistent_edge_count,
                      closed ? YesNo(outward_oriented) : "n/a (open)");
  text +=
      fmt::format("topology:   {} components, Euler characteristic {}, genus {}\n", component_count,
                  euler_characteristic, genus >= 0 ? std::to_string(genus) : "undefined");
  text += fmt::format("volume:     {:.9g} (signed{})\n", signed_volume,
                      closed ? "" : "; not enclosed: open surface");
  text += fmt::format("area:       {:.9g}\n", surface_area);
  text += fmt::format("bounds:     [{:.6g}, {:.6g}, {:.6g}] .. [{:.6g}, {:.6g}, {:.6g}]\n",
                      bbox_min.x(), bbox_min.y(), bbox_min.z(), bbox_max.x(), bbox_max.y(),
                      bbox_max.z());
  text +=
      fmt::format("edges:      length min {:.6g}, mean {:.6g}, max {:.6g}; {} degenerate faces\n",
                  min_edge_length, mean_edge_length, max_edge_length, degenerate_face_count);
  text += fmt::format("self-intersections (CGAL):   {}\n", CheckLine(cgal));
  text += fmt::format("self-intersections (TetGen): {}\n", CheckLine(tetgen));
  if (cgal.ran && tetgen.ran)
    text += fmt::format("checks agree: {}{}\n", YesNo(self_intersection_checks_agree),
                        self_intersection_checks_agree && !self_intersecting_faces_agree
                            ? " (different faces)"
                            : "");
  if (!topology_message.empty()) text += "MeshTopology: " + topology_message + "\n";
  for (const std::string& warning : warnings) text += "warning: " + warning + "\n";
  for (const std::string& problem : problems) text += "problem: " + problem + "\n";
  text += std::string("verdict: ") + (valid() ? "valid" : "INVALID") + "\n";
  return text;
}

std::string MeshValidationReport::ToJson(int indent) const {
  using Json = nlohmann::ordered_json;
  auto number = [](double value) { return std::isfinite(value) ? Json(value) : Json(nullptr); };
  Json json;
  json["valid"] = valid();
  json["problems"] = problems;
  json["warnings"] = warnings;
  json["counts"] = {{"vertices", vertex_count},
                    {"faces", face_count},
                    {"edges", edge_count},
                    {"unreferenced_vertices", unreferenced_vertex_count},
                    {"non_finite_vertices", non_finite_vertex_count},
                    {"faces_repeating_a_vertex", repeated_vertex_face_count}};
  json["topology"] = {{"closed", closed},
                      {"boundary_edges", boundary_edge_count},
                      {"boundary_loops", boundary_loop_count},
                      {"manifold", manifold},
                      {"non_manifold_edges", non_manifold_edge_count},
                      {"non_manifold_vertices", non_manifold_vertex_count},
                      {"consistently_oriented", consistently_oriented},
                      {"inconsistent_edges", inconsistent_edge_count},
                      {"components", component_count},
                      {"euler_characteristic", euler_characteristic},
                      {"genus", genus >= 0 ? Json(genus) : Json(nullptr)},
                      {"mesh_topology_message", topology_message}};
  json["geometry"] = {
      {"signed_volume", number(signed_volume)},
      {"outward_oriented", outward_oriented},
      {"surface_area", number(surface_area)},
      {"bbox_min", {number(bbox_min.x()), number(bbox_min.y()), number(bbox_min.z())}},
      {"bbox_max", {number(bbox_max.x()), number(bbox_max.y()), number(bbox_max.z())}},
      {"edge_length",
       {{"min", number(min_edge_length)},
        {"mean", number(mean_edge_length)},
        {"max", number(max_edge_length)}}},
      {"degenerate_faces", degenerate_face_count}};
  const int examples = 10;
  json["self_intersections"] = {{"cgal", CheckJson(cgal, examples)},
                                {"tetgen", CheckJson(tetgen, examples)},
                                {"checks_agree", self_intersection_checks_agree},
                                {"faces_agree", self_intersecting_faces_agree}};
  return json.dump(indent);
}

}  // namespace subflow::geometry
