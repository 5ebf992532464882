#include "io/json_io.h"

#include <visp3/core/vpThetaUVector.h>
#include <visp3/core/vpTranslationVector.h>

#include <stdexcept>

#include "detector/lens.h"

namespace oal {

Json PointJson(const Point2d& point) {
  return Json::array({point.u, point.v});
}

Json LineJson(const LineParams& line) {
  return Json{{"rho", line.rho_px}, {"theta", line.theta_rad}};
}

Json DetectedLineJson(const DetectedLine& line) {
  return Json{{"rho", line.line.rho_px},       {"theta", line.line.theta_rad},
              {"votes", line.votes},           {"count", line.count},
              {"borders", line.borders},       {"support", line.support},
              {"width", line.width_px},        {"end_a", PointJson(line.end_a)},
              {"end_b", PointJson(line.end_b)}};
}

Json TruthLineJson(const TruthLine& line) {
  return Json{{"index", line.index},
              {"visible", line.visible},
              {"ideal", LineJson(line.ideal)},
              {"distorted_fit", LineJson(line.distorted_fit)},
              {"end_a", PointJson(line.end_a)},
              {"end_b", PointJson(line.end_b)},
              {"visible_length_px", line.visible_length_px},
              {"width_px", line.width_px}};
}

Json PoseJson(const vpHomogeneousMatrix& cMo) {
  Json matrix = Json::array();
  for (unsigned int row = 0; row < 4; ++row) {
    matrix.push_back(Json::array({cMo[row][0], cMo[row][1], cMo[row][2], cMo[row][3]}));
  }
  const vpTranslationVector t = cMo.getTranslationVector();
  const vpThetaUVector tu = cMo.getThetaUVector();
  return Json{{"matrix", matrix},
              {"t_m", Json::array({t[0], t[1], t[2]})},
              {"thetau_rad", Json::array({tu[0], tu[1], tu[2]})}};
}

Json CameraJson(const Lens& camera, int width, int height) {
  Json json{{"model", LensModelName(camera)},
            {"px", camera.px()},
            {"py", camera.py()},
            {"u0", camera.u0()},
            {"v0", camera.v0()},
            {"kud", camera.kud()},
            {"kdu", camera.kdu()},
            {"width", width},
            {"height", height}};
  if (camera.model() == Lens::Model::kOpenCV) {
    const auto c = camera.distortion().ToArray();
    json["distortion_coefficients"] = camera.distortion().IsRational()
                                          ? Json(c)
                                          : Json(std::vector<double>(c.begin(), c.begin() + 5));
  }
  return json;
}

void WriteJsonLine(std::ostream& sink, const Json& record, bool flush) {
  sink << record.dump() << '\n';
  if (flush) sink.flush();
  if (!sink) throw std::runtime_error("cannot write the output");
}

void WriteText(std::ostream& sink, const std::string& text) {
  sink << text;
  sink.flush();
  if (!sink) throw std::runtime_error("cannot write the output");
}

Json ScanJson(const TargetFrame& result, ScanMode mode) {
  Json region = Json::array();
  for (const Point2d& p : result.region) region.push_back(PointJson(p));
  return Json{{"mode", ToString(mode)},
              {"source", ToString(result.source)},
              {"borders", result.borders},
              {"candidates", result.candidates},
              {"region", std::move(region)}};
}

}  // namespace oal
