#include "vision/import_qualisys.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <pugixml.hpp>

#include "core/error.h"
#include "vision/camera.h"
#include "vision/natural_order.h"

namespace subflow::vision {
namespace {

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

class QcaCamera {
 public:
  QcaCamera(const pugi::xml_node& camera, std::string source, std::string name)
      : camera_(camera), source_(std::move(source)), name_(std::move(name)) {}

  pugi::xml_node Child(const char* element) const {
    const pugi::xml_node child = camera_.child(element);
    if (!child)
      ThrowError(source_, Field(element), std::string("missing element <") + element + "> (Qualisys .qca.txt)");
    return child;
  }

  double Number(const pugi::xml_node& node, const char* attribute) const {
    const pugi::xml_attribute a = node.attribute(attribute);
    const std::string field = Field(std::string(node.name()) + "." + attribute);
    if (!a) ThrowError(source_, field, "missing attribute (expected a number)");
    double value = 0;
    if (!ParseFiniteNumber(a.value(), &value))
      ThrowError(source_, field, std::string("expected a finite number, got \"") + a.value() + "\"");
    return value;
  }

  std::string Field(const std::string& what) const { return "camera \"" + name_ + "\": " + what; }

 private:
  pugi::xml_node camera_;
  std::string source_, name_;
};

CalibratedCamera ReadCamera(const QcaCamera& qca, const std::string& name, const std::string& source,
                            const QualisysImportOptions& options, Calibration* calibration) {
  const double b = options.binning_factor;
  CalibratedCamera camera;
  camera.name = name;
  camera.source = source;
  const pugi::xml_node fov = qca.Child("fov_video");
  const double left = qca.Number(fov, "left"), top = qca.Number(fov, "top");
  const std::string binning = " at binning factor " + std::to_string(options.binning_factor) + ")";
  camera.width = ImageSideFromNumber((qca.Number(fov, "right") - left + 1) / b, source,
                                     qca.Field("fov_video: image width (right − left + 1" + binning));
  camera.height = ImageSideFromNumber((qca.Number(fov, "bottom") - top + 1) / b, source,
                                      qca.Field("fov_video: image height (bottom − top + 1" + binning));

  const pugi::xml_node intrinsic = qca.Child("intrinsic");
  const double unit = 64.0 * b;  // QTM's sub-pixel units per (binned) pixel
  const double skew = qca.Number(intrinsic, "skew");
  if (skew != 0)
    ThrowError(source, qca.Field("intrinsic.skew"),
               "expected 0 (Pose2Sim ignores the skew and its unit is not documented), got " +
                   std::to_string(skew));
  camera.K << qca.Number(intrinsic, "focalLengthU") / unit, 0, qca.Number(intrinsic, "centerPointU") / unit - left,
      0, qca.Number(intrinsic, "focalLengthV") / unit, qca.Number(intrinsic, "centerPointV") / unit - top, 0, 0, 1;
  const double scale = options.raw_distortion ? 1.0 : unit;
  camera.distortion.resize(5);
  camera.distortion << qca.Number(intrinsic, "radialDistortion1") / scale,
      qca.Number(intrinsic, "radialDistortion2") / scale, qca.Number(intrinsic, "tangentalDistortion1") / scale,
      qca.Number(intrinsic, "tangentalDistortion2") / scale,
      (intrinsic.attribute("radialDistortion3") ? qca.Number(intrinsic, "radialDistortion3") : 0.0) / scale;
  if (camera.distortion[4] != 0)
    calibration->notes.push_back("camera \"" + name + "\": radialDistortion3 kept as k3 (Pose2Sim drops it)");

  const pugi::xml_node transform = qca.Child("transform");
  Eigen::Matrix3d M;
  const char* entries[] = {"r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33"};
  for (int i = 0; i < 9; ++i) M(i / 3, i % 3) = qca.Number(transform, entries[i]);
  const Eigen::Vector3d centre(qca.Number(transform, "x"), qca.Number(transform, "y"), qca.Number(transform, "z"));
  camera.R = Eigen::Vector3d(1, -1, -1).asDiagonal() * M;
  camera.t = -camera.R * (centre / 1000.0);
  return camera;
}

}  // namespace

Calibration ParseQualisysCalibration(const std::string& text, const std::string& source,
                                     const QualisysImportOptions& options) {
  if (options.binning_factor < 1)
    ThrowError(source, "binning factor", "expected a positive integer, got " + std::to_string(options.binning_factor));
  pugi::xml_document document;
  const pugi::xml_parse_result parsed = document.load_buffer(text.data(), text.size());
  if (!parsed)
    ThrowError(source, "XML at byte " + std::to_string(parsed.offset),
               std::string("expected a Qualisys calibration (XML): ") + parsed.description());
  const pugi::xml_node cameras = document.child("calibration").child("cameras");
  if (!cameras)
    ThrowError(source, "<calibration><cameras>", "missing (expected a Qualisys .qca.txt calibration)");
  Calibration calibration;
  calibration.format = "qualisys";
  calibration.units = "m";
  calibration.up = Eigen::Vector3d::UnitZ();
  std::vector<std::string> skipped;
  for (const pugi::xml_node& node : cameras.children("camera")) {
    const std::string name = node.attribute("serial").value();
    if (name.empty()) ThrowError(source, "<camera> serial", "missing (expected the camera's serial, its name)");
    const std::string model = Lower(node.attribute("model").value());
    if (model.find("video") == std::string::npos && model.find("hybrid") == std::string::npos &&
        model.find("none") == std::string::npos) {
      skipped.push_back(name + " (model \"" + node.attribute("model").value() + "\")");
      continue;
    }
    const QcaCamera qca(node, source, name);
    const std::string rotation = node.attribute("viewrotation").value();
    if (!rotation.empty() && rotation != "0")
      calibration.notes.push_back("camera \"" + name + "\": viewrotation " + rotation +
                                  " ignored, as Pose2Sim does (its video must be stored as calibrated)");
    calibration.cameras.push_back(ReadCamera(qca, name, source, options, &calibration));
  }
  if (!skipped.empty()) {
    std::string list;
    for (const std::string& s : skipped) list += (list.empty() ? "" : ", ") + s;
    calibration.notes.push_back("marker-only cameras left out (as Pose2Sim does): " + list);
  }
  if (calibration.cameras.empty())
    ThrowError(source, "<cameras>", "no video camera (expected <camera model=\"...video...\"> or model \"none\")");
  std::stable_sort(calibration.cameras.begin(), calibration.cameras.end(),
                   [](const CalibratedCamera& a, const CalibratedCamera& b) { return NaturalLess(a.name, b.name); });
  calibration.notes.push_back(
      std::string("Qualisys as Pose2Sim reads it: 1/64-pixel units") +
      (options.binning_factor > 1 ? " at binning " + std::to_string(options.binning_factor) : "") +
      ", principal point relative to fov_video, distortion " +
      (options.raw_distortion ? "as printed" : "divided by 64 (Pose2Sim)") +
      ", camera frame rotated by π about x, mm → m, z up");
  CheckCameraNames(calibration, source);
  return calibration;
}

Calibration ReadQualisysCalibration(const std::string& path, const QualisysImportOptions& options) {
  return ParseQualisysCalibration(ReadCalibrationFile(path, "a Qualisys .qca.txt calibration"), path, options);
}

}  // namespace subflow::vision
