#include "detector/accumulator_list.h"

#include <algorithm>
#include <cmath>

namespace oal {
namespace {

// Signed angle whose sine is `s`, for |s| <= sin(45 deg): asin's Taylor series to s^9, exact
// to 1e-9 rad over the angles anglechange allows.
double SmallAsin(double s) {
  const double s2 = s * s;
  return s * (1.0 + s2 * (1.0 / 6.0 + s2 * (3.0 / 40.0 + s2 * (5.0 / 112.0 + s2 * 35.0 / 1152.0))));
}

// Rotates the unit vector (c, s) by a small angle a, with sin/cos series good to 1e-12 for
// |a| < 0.1 rad, and renormalises.
void RotateSmall(double a, double* c, double* s) {
  const double a2 = a * a;
  const double cos_a = 1.0 - a2 / 2.0 + a2 * a2 / 24.0 - a2 * a2 * a2 / 720.0;
  const double sin_a = a * (1.0 - a2 / 6.0 + a2 * a2 / 120.0 - a2 * a2 * a2 / 5040.0);
  const double new_c = *c * cos_a - *s * sin_a;
  const double new_s = *s * cos_a + *c * sin_a;
  const double norm = 1.0 / std::sqrt(new_c * new_c + new_s * new_s);
  *c = new_c * norm;
  *s = new_s * norm;
}

}  // namespace

OrderedAccumulatorList::OrderedAccumulatorList(double angle_change_rad, double r_change_px,
                                               int max_lines, int capacity)
    : cos_angle_change_(std::cos(angle_change_rad)),
      sin_angle_change_(std::sin(angle_change_rad)),
      r_change_px_(r_change_px),
      max_lines_(max_lines),
      capacity_(std::max(capacity, max_lines)) {
  entries_.reserve(static_cast<std::size_t>(capacity_));
  match_cos_.assign(static_cast<std::size_t>(capacity_), 0.0f);
  match_sin_.assign(static_cast<std::size_t>(capacity_), 0.0f);
  match_rho_.assign(static_cast<std::size_t>(capacity_), 0.0f);
}

void OrderedAccumulatorList::Mirror(std::size_t i) {
  match_cos_[i] = static_cast<float>(entries_[i].cos_theta);
  match_sin_[i] = static_cast<float>(entries_[i].sin_theta);
  match_rho_[i] = static_cast<float>(entries_[i].rho_px);
}

void OrderedAccumulatorList::MirrorAll() {
  for (std::size_t i = 0; i < entries_.size(); ++i) Mirror(i);
}

int OrderedAccumulatorList::FirstMatch(double cos_theta, double sin_theta, double rho_px) const {
  const float c = static_cast<float>(cos_theta), s = static_cast<float>(sin_theta);
  const float rho = static_cast<float>(rho_px);
  const float cos_limit = static_cast<float>(cos_angle_change_);
  const float r_limit = static_cast<float>(r_change_px_);
  const int size = static_cast<int>(entries_.size());
  for (int i = 0; i < size; ++i) {
    const float dot = match_cos_[i] * c + match_sin_[i] * s;
    if (std::fabs(dot) < cos_limit) continue;  // Eq. 1
    // A negative dot is the same line with its normal reversed: theta +- pi, -rho.
    const float aligned_rho = dot < 0.0f ? -rho : rho;
    if (std::fabs(aligned_rho - match_rho_[i]) > r_limit) continue;  // Eq. 2
    return i;
  }
  return -1;
}

int OrderedAccumulatorList::Vote(double cos_theta, double sin_theta, double rho_px, int border) {
  const int size = static_cast<int>(entries_.size());
  const int i = FirstMatch(cos_theta, sin_theta, rho_px);
  if (i >= 0) {
    OalEntry& entry = entries_[static_cast<std::size_t>(i)];
    const double sign =
        entry.cos_theta * cos_theta + entry.sin_theta * sin_theta < 0.0 ? -1.0 : 1.0;
    const double rho = sign * rho_px;
    const double c = sign * cos_theta, s = sign * sin_theta;
    const double cross = entry.cos_theta * s - entry.sin_theta * c;  // sin(theta_new - theta_old)
    const double prior = static_cast<double>(entry.weight);
    const double step = SmallAsin(cross) / (prior + 1.0);
    entry.theta_rad += step;
    RotateSmall(step, &entry.cos_theta, &entry.sin_theta);
    entry.rho_px = (prior * entry.rho_px + rho) / (prior + 1.0);
    if (entry.theta_rad < 0.0 || entry.theta_rad >= kPi) {  // keep theta in [0, pi)
      entry.theta_rad += entry.theta_rad < 0.0 ? kPi : -kPi;
      entry.rho_px = -entry.rho_px;
      entry.cos_theta = -entry.cos_theta;
      entry.sin_theta = -entry.sin_theta;
    }
    ++entry.weight;
    if (entry.last_border != border) {
      ++entry.borders;
      entry.last_border = border;
    }
    Mirror(static_cast<std::size_t>(i));
    return i;
  }
  if (size >= capacity_) return -1;
  OalEntry entry;
  if (sin_theta < 0.0 || (sin_theta == 0.0 && cos_theta < 0.0)) {
    cos_theta = -cos_theta;
    sin_theta = -sin_theta;
    rho_px = -rho_px;
  }
  entry.cos_theta = cos_theta;
  entry.sin_theta = sin_theta;
  entry.theta_rad = std::atan2(sin_theta, cos_theta);
  if (entry.theta_rad >= kPi) entry.theta_rad = 0.0;
  entry.rho_px = rho_px;
  entry.last_border = border;
  entries_.push_back(entry);
  Mirror(entries_.size() - 1);
  return size;
}

void OrderedAccumulatorList::SortAndCull() {
  // Insertion sort: stable, allocation-free, and near-linear because the order changes
  // little from one border to the next (the paper's argument for reordering each border).
  for (std::size_t i = 1; i < entries_.size(); ++i) {
    OalEntry moving = entries_[i];
    std::size_t j = i;
    while (j > 0 && entries_[j - 1].Score() < moving.Score()) {
      entries_[j] = entries_[j - 1];
      --j;
    }
    entries_[j] = moving;
  }
  while (static_cast<int>(entries_.size()) > max_lines_ && entries_.back().Score() < 0.0) {
    entries_.pop_back();
  }
  MirrorAll();
}

}  // namespace oal
