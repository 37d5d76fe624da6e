// probe: per frame, result mesh vs the shape stage's hull: fraction of hull vertices within d of the result, and of result vertices within d of the hull
#include <cstdio>
#include <cstdlib>
#include <gtest/gtest.h>
#include "geometry/closest_point.h"
#include "geometry/mesh_io.h"
namespace subflow {
TEST(ZZ, HullCover) {
  const char* R = std::getenv("ZZ_RESULT"); const char* H = std::getenv("ZZ_HULL");
  if (!R || !H) GTEST_SKIP();
  const double d = std::atof(std::getenv("ZZ_D") ? std::getenv("ZZ_D") : "0.05");
  const int n = std::atoi(std::getenv("ZZ_N") ? std::getenv("ZZ_N") : "100");
  const int step = std::atoi(std::getenv("ZZ_STEP") ? std::getenv("ZZ_STEP") : "1");
  geometry::MeshReadOptions o; o.require_manifold = false;
  double sc = 0, sa = 0; int k = 0;
  for (int f = 0; f < n; f += step) {
    char name[32]; std::snprintf(name, sizeof name, "/%06d.ply", f);
    const auto r = geometry::ReadMesh(std::string(R) + name, o);
    const auto h = geometry::ReadMesh(std::string(H) + name, o);
    geometry::ClosestPointTree tr(r), th(h);
    const Eigen::VectorXd dh = tr.Distances(h.V), dr = th.Distances(r.V);
    const double cover = (dh.array() < d).cast<double>().mean(), acc = (dr.array() < d).cast<double>().mean();
    std::printf("frame %d hull_covered %.3f result_near_hull %.3f\n", f, cover, acc);
    sc += cover; sa += acc; ++k;
  }
  std::printf("MEAN hull_covered %.4f result_near_hull %.4f\n", sc / k, sa / k);
}
}  // namespace subflow
