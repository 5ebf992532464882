#include "detector/options.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace oal {
namespace {

template <typename T>
void Require(bool ok, const char* field, T value, const char* constraint) {
  RequireOption(ok, std::string("DetectorOptions::") + field, value, constraint);
}

}  // namespace

std::string ToString(Polarity polarity) {
  switch (polarity) {
    case Polarity::kDarkLines:
      return "dark";
    case Polarity::kLightLines:
      return "light";
    case Polarity::kEdges:
      return "edges";
  }
  return "?";
}

std::string ToString(ThresholdMode mode) {
  return mode == ThresholdMode::kFixed ? "fixed" : "otsu";
}

Polarity PolarityFromString(const std::string& text) {
  if (text == "dark") return Polarity::kDarkLines;
  if (text == "light") return Polarity::kLightLines;
  if (text == "edges") return Polarity::kEdges;
  throw std::invalid_argument("polarity '" + text + "' is not one of: dark, light, edges");
}

ThresholdMode ThresholdModeFromString(const std::string& text) {
  if (text == "fixed") return ThresholdMode::kFixed;
  if (text == "otsu") return ThresholdMode::kOtsu;
  throw std::invalid_argument("threshold mode '" + text + "' is not one of: fixed, otsu");
}

void DetectorOptions::Check() const {
  Require(start_px >= 0 && start_px <= 1000, "start_px", start_px, "0 <= start_px <= 1000");
  Require(step_px >= 1 && step_px <= 1000, "step_px", step_px, "1 <= step_px <= 1000");
  Require(fixed_threshold >= 1 && fixed_threshold <= 255, "fixed_threshold", fixed_threshold,
          "1 <= fixed_threshold <= 255");
  Require(min_contrast >= 0 && min_contrast <= 255, "min_contrast", min_contrast,
          "0 <= min_contrast <= 255");
  Require(min_relative_contrast >= 0.0 && min_relative_contrast <= 1.0, "min_relative_contrast",
          min_relative_contrast, "0 <= min_relative_contrast <= 1");
  Require(min_width_px > 0 && min_width_px <= 1000, "min_width_px", min_width_px,
          "0 < min_width_px <= 1000");
  Require(max_width_px >= min_width_px && max_width_px <= 1000, "max_width_px", max_width_px,
          "min_width_px <= max_width_px <= 1000");
  Require(min_crossing_angle_deg >= 1 && min_crossing_angle_deg <= 90, "min_crossing_angle_deg",
          min_crossing_angle_deg, "1 <= min_crossing_angle_deg <= 90");
  Require(max_points_per_border >= 2 && max_points_per_border <= 64, "max_points_per_border",
          max_points_per_border, "2 <= max_points_per_border <= 64");
  Require(region_max_borders >= 0 && region_max_borders <= 1000, "region_max_borders",
          region_max_borders, "0 <= region_max_borders <= 1000");
  Require(region_sample_step >= 1 && region_sample_step <= 16, "region_sample_step",
          region_sample_step, "1 <= region_sample_step <= 16");
  Require(
      max_pair_width_ratio == 0.0 || (max_pair_width_ratio >= 1.0 && max_pair_width_ratio <= 100.0),
      "max_pair_width_ratio", max_pair_width_ratio,
      "max_pair_width_ratio == 0 or 1 <= max_pair_width_ratio <= 100");
  Require(angle_change_deg > 0 && angle_change_deg <= 45, "angle_change_deg", angle_change_deg,
          "0 < angle_change_deg <= 45");
  Require(r_change_px > 0 && r_change_px <= 1000, "r_change_px", r_change_px,
          "0 < r_change_px <= 1000");
  Require(max_lines >= 1 && max_lines <= 1000, "max_lines", max_lines, "1 <= max_lines <= 1000");
  Require(support_tolerance_px > 0 && support_tolerance_px <= 100, "support_tolerance_px",
          support_tolerance_px, "0 < support_tolerance_px <= 100");
  Require(max_output_lines >= 1 && max_output_lines <= 1000, "max_output_lines", max_output_lines,
          "1 <= max_output_lines <= 1000");
  Require(min_votes >= 1 && min_votes <= 100000, "min_votes", min_votes,
          "1 <= min_votes <= 100000");
  Require(min_support >= 2 && min_support <= 100000, "min_support", min_support,
          "2 <= min_support <= 100000");
  Require(duplicate_angle_deg > 0 && duplicate_angle_deg <= 90, "duplicate_angle_deg",
          duplicate_angle_deg, "0 < duplicate_angle_deg <= 90");
  Require(duplicate_r_px > 0 && duplicate_r_px <= 1000, "duplicate_r_px", duplicate_r_px,
          "0 < duplicate_r_px <= 1000");
}

double ContrastNeeded(int min_contrast, double min_relative_contrast, double light) {
  return std::min(static_cast<double>(min_contrast), min_relative_contrast * light);
}

double DetectorOptions::ContrastNeededAt(double light) const {
  return ContrastNeeded(min_contrast, min_relative_contrast, light);
}

DetectorOptions DetectorOptions::ScaledBy(double scale) const {
  RequireOption(scale > 0.0 && scale <= 100.0, "DetectorOptions::ScaledBy scale", scale,
                "0 < scale <= 100");
  DetectorOptions scaled = *this;
  const auto whole = [scale](int px, int at_least) {
    return std::max(at_least, static_cast<int>(std::lround(px * scale)));
  };
  scaled.start_px = whole(start_px, 0);
  scaled.step_px = whole(step_px, 1);
  scaled.min_width_px = std::max(1.0, min_width_px * scale);
  scaled.max_width_px = std::max(scaled.min_width_px, max_width_px * scale);
  scaled.r_change_px = r_change_px * scale;
  scaled.support_tolerance_px = support_tolerance_px * scale;
  scaled.duplicate_r_px = duplicate_r_px * scale;
  scaled.region_sample_step = std::clamp(static_cast<int>(region_sample_step * scale), 1, 16);
  return scaled;
}

DetectorOptions DetectorOptions::Paper() {
  DetectorOptions options;
  options.min_crossing_angle_deg = 90.0;
  options.skip_same_side_pairs = false;
  options.max_pair_width_ratio = 0.0;
  options.count_visible_borders_only = false;
  options.refit_lines = false;
  options.rank_by_support = false;
  return options;
}

}  // namespace oal
