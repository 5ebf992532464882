#include "eval/rendered/marker_method.h"

#include <stdexcept>
#include <utility>

#include "detector/lens.h"
#include "eval/rendered/apriltag_method.h"
#include "eval/rendered/charuco_method.h"

namespace oal {
namespace {

const std::pair<SheetMarker, const char*> kMarkerNames[] = {
    {SheetMarker::kOal, "oal"},
    {SheetMarker::kAprilTag, "apriltag"},
    {SheetMarker::kCharuco, "charuco"},
};

}  // namespace

std::string ToString(SheetMarker marker) {
  for (const auto& [value, name] : kMarkerNames) {
    if (value == marker) return name;
  }
  throw std::invalid_argument("SheetMarker: not one of the markers");
}

SheetMarker SheetMarkerFromString(const std::string& text) {
  for (const auto& [value, name] : kMarkerNames) {
    if (text == name) return value;
  }
  throw std::invalid_argument("unknown marker '" + text + "' (accepted: " + SheetMarkerNameList() +
                              ")");
}

std::string SheetMarkerNameList() {
  std::string list;
  for (const auto& [value, name] : kMarkerNames)
    list += (list.empty() ? "" : ", ") + std::string(name);
  return list;
}

std::string ToString(MarkerStatus status) {
  switch (status) {
    case MarkerStatus::kOk:
      return "ok";
    case MarkerStatus::kNotFound:
      return "not-found";
    case MarkerStatus::kNoPose:
      return "no-pose";
  }
  return "unknown";
}

std::unique_ptr<MarkerMethod> MakeMarkerMethod(SheetMarker marker, const LineTarget& sheet,
                                               const Lens& camera, int width, int height) {
  switch (marker) {
    case SheetMarker::kAprilTag:
      return MakeAprilTagMethod(sheet, camera, width, height);
    case SheetMarker::kCharuco:
      return MakeCharucoMethod(sheet, camera, width, height);
    case SheetMarker::kOal:
      break;
  }
  throw std::invalid_argument("MakeMarkerMethod: '" + ToString(marker) +
                              "' is our target, found by the target tracker, not a printed marker");
}

LineTarget MarkerSheet(const LineTarget& sheet, const MarkerMethod& method) {
  LineTarget board = sheet;
  board.name = method.Name();
  board.lines.clear();
  return board;
}

}  // namespace oal
