// RayCaster on Embree 3: one device for the process, one scene of one triangle geometry
// per caster, robust (watertight) traversal.
#include "geometry/ray_caster.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include <embree3/rtcore.h>

#include "core/error.h"

namespace subflow::geometry {
namespace {

// The process's Embree device, made on first use (function-local static: thread-safe).
RTCDevice Device() {
  static const RTCDevice device = [] {
    RTCDevice made = rtcNewDevice("verbose=0");
    if (!made) ThrowError("Embree", "device", "could not be created (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
    return made;
  }();
  return device;
}

void CheckDevice(const char* what) {
  const RTCError error = rtcGetDeviceError(Device());
  if (error != RTC_ERROR_NONE) ThrowError("Embree", what, "failed (error " + std::to_string(error) + ")");
}

}  // namespace

struct RayCaster::Impl {
  const TriangleMesh* mesh = nullptr;  // the caller's, read for the hits in double
  std::vector<int> faces;      // scene primitive i is row faces[i] of F
  Eigen::Vector3d centre;      // the scene's vertices are V − centre, in float
  float slack = 0.0f;          // float rounding of the mesh, in world units
  RTCScene scene = nullptr;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
  }
};

RayCaster::RayCaster(const TriangleMesh& mesh, std::vector<int> faces) : impl_(std::make_unique<Impl>()) {
  Impl& impl = *impl_;
  impl.mesh = &mesh;
  impl.faces = std::move(faces);
  const Eigen::Vector3d low = mesh.V.colwise().minCoeff(), high = mesh.V.colwise().maxCoeff();
  impl.centre = 0.5 * (low + high);
  const double extent = (high - low).maxCoeff();
  impl.slack = static_cast<float>(1e-6 * std::max(extent, 1e-30));

  impl.scene = rtcNewScene(Device());
  CheckDevice("scene");
  rtcSetSceneFlags(impl.scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geometry = rtcNewGeometry(Device(), RTC_GEOMETRY_TYPE_TRIANGLE);
  CheckDevice("triangle geometry");
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), static_cast<std::size_t>(mesh.vertex_count())));
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), impl.faces.size()));
  CheckDevice("geometry buffers");
  for (int v = 0; v < mesh.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k) vertices[3 * v + k] = static_cast<float>(mesh.V(v, k) - impl.centre(k));
  for (std::size_t i = 0; i < impl.faces.size(); ++i)
    for (int k = 0; k < 3; ++k) indices[3 * i + k] = static_cast<unsigned>(mesh.F(impl.faces[i], k));
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(impl.scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(impl.scene);
  CheckDevice("scene build");
}

RayCaster::~RayCaster() = default;
RayCaster::RayCaster(RayCaster&&) noexcept = default;
RayCaster& RayCaster::operator=(RayCaster&&) noexcept = default;

RayHit RayCaster::Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& unit_direction, double max_t) const {
  const Impl& impl = *impl_;
  RTCRayHit query;
  const Eigen::Vector3d local = origin - impl.centre;
  query.ray.org_x = static_cast<float>(local.x());
  query.ray.org_y = static_cast<float>(local.y());
  query.ray.org_z = static_cast<float>(local.z());
  query.ray.dir_x = static_cast<float>(unit_direction.x());
  query.ray.dir_y = static_cast<float>(unit_direction.y());
  query.ray.dir_z = static_cast<float>(unit_direction.z());
  query.ray.tnear = 0.0f;
  // A little beyond max_t: the float scene may place a hit just below max_t just above it.
  query.ray.tfar = std::isfinite(max_t) && max_t < 1e30
                       ? std::nextafter(static_cast<float>(max_t * (1.0 + 1e-6)) + 2.0f * impl.slack, INFINITY)
                       : INFINITY;
  query.ray.mask = 0xFFFFFFFFu;
  query.ray.flags = 0;
  query.ray.time = 0.0f;
  query.ray.id = 0;
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  query.hit.primID = RTC_INVALID_GEOMETRY_ID;
  query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcIntersect1(impl.scene, &context, &query);

  RayHit result;
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return result;
  const int face = impl.faces[query.hit.primID];
  // The hit's parameter again in double, on the plane of the triangle Embree chose.
  const Positions& V = impl.mesh->V;
  const Faces& F = impl.mesh->F;
  const Eigen::Vector3d a = V.row(F(face, 0)), b = V.row(F(face, 1)), c = V.row(F(face, 2));
  const Eigen::Vector3d normal = (b - a).cross(c - a);
  const double along = normal.dot(unit_direction);
  double t = query.ray.tfar;
  if (std::abs(along) > 1e-6 * normal.norm()) t = normal.dot(a - origin) / along;
  result.hit = true;
  result.t = std::max(0.0, t);
  result.point = origin + result.t * unit_direction;
  result.face = face;
  result.barycentric = FaceBarycentric(*impl.mesh, face, result.point);
  return result;
}

}  // namespace subflow::geometry
