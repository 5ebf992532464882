// Step 1 of the pose (pose.h): identification of the detected lines as target lines 1-4, and
// the options' check.

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "base/angles.h"
#include "detector/lens.h"
#include "servo/pose.h"
#include "servo/pose_internal.h"

namespace oal {
namespace {

using pose_internal::HashTarget;
using pose_internal::Vec2;

constexpr double kInf = std::numeric_limits<double>::infinity();

bool InRange(double value, double lo, double hi) {
  return value >= lo && value <= hi;
}

double Cross(const Vec2& a, const Vec2& b) {
  return a.x * b.y - a.y * b.x;
}
Vec2 Minus(const Vec2& a, const Vec2& b) {
  return {a.x - b.x, a.y - b.y};
}

// 3x3 matrices, row major, for the homographies of step 1 (cheaper than vpMatrix here).
using Mat3 = std::array<double, 9>;

Mat3 Multiply(const Mat3& a, const Mat3& b) {
  Mat3 c{};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
      c[3 * r + k] = a[3 * r] * b[k] + a[3 * r + 1] * b[3 + k] + a[3 * r + 2] * b[6 + k];
  return c;
}

// Inverse up to scale (the adjugate): enough for homographies.
Mat3 Adjugate(const Mat3& m) {
  return {m[4] * m[8] - m[5] * m[7], m[2] * m[7] - m[1] * m[8], m[1] * m[5] - m[2] * m[4],
          m[5] * m[6] - m[3] * m[8], m[0] * m[8] - m[2] * m[6], m[2] * m[3] - m[0] * m[5],
          m[3] * m[7] - m[4] * m[6], m[1] * m[6] - m[0] * m[7], m[0] * m[4] - m[1] * m[3]};
}

// Applies a homography; false when the point maps to infinity.
bool Apply(const Mat3& h, double x, double y, Vec2* out) {
  const double w = h[6] * x + h[7] * y + h[8];
  if (!(std::fabs(w) > 1e-300)) return false;
  out->x = (h[0] * x + h[1] * y + h[2]) / w;
  out->y = (h[3] * x + h[4] * y + h[5]) / w;
  return std::isfinite(out->x) && std::isfinite(out->y);
}

// The projective map of the unit square onto the quadrilateral p0 p1 p2 p3 with
// (0,0) -> p0, (1,0) -> p1, (1,1) -> p2, (0,1) -> p3 (Heckbert's closed form).
Mat3 SquareToQuad(const Vec2& p0, const Vec2& p1, const Vec2& p2, const Vec2& p3) {
  const double sx = p0.x - p1.x + p2.x - p3.x, sy = p0.y - p1.y + p2.y - p3.y;
  const double dx1 = p1.x - p2.x, dx2 = p3.x - p2.x, dy1 = p1.y - p2.y, dy2 = p3.y - p2.y;
  const double den = dx1 * dy2 - dx2 * dy1;
  const double g = (sx * dy2 - sy * dx2) / den, h = (dx1 * sy - dy1 * sx) / den;
  return {p1.x - p0.x + g * p1.x,
          p3.x - p0.x + h * p3.x,
          p0.x,
          p1.y - p0.y + g * p1.y,
          p3.y - p0.y + h * p3.y,
          p0.y,
          g,
          h,
          1.0};
}

// One 4-subset of the detected lines, evaluated by the rule of pose.h.
struct SubsetResult {
  PoseStatus status = PoseStatus::kDegenerate;
  std::string message;
  std::array<int, 4> line_index{{-1, -1, -1, -1}};
  std::array<Point2d, 4> corners_px{};
  double cost = kInf, margin = 0.0;
};

class Identifier {
 public:
  Identifier(const std::vector<DetectedLine>& lines, const HashTarget& target,
             const PoseOptions& options, const vpRotationMatrix* previous_cRo)
      : lines_(lines), target_(target), options_(options), previous_cRo_(previous_cRo) {
    const Lens& camera = options.camera;
    k_inv_ = {1.0 / camera.px(),
              0.0,
              -camera.u0() / camera.px(),
              0.0,
              1.0 / camera.py(),
              -camera.v0() / camera.py(),
              0.0,
              0.0,
              1.0};
  }

  SubsetResult Evaluate(const std::array<int, 4>& idx) const;

 private:
  // The four lines in two groups of crossing lines, G and H (indices into lines_).
  struct Groups {
    std::array<int, 2> g{}, h{};
  };
  // The corners q[i][j] = G_i ∩ H_j, pixels, and the sign of the quadrilateral's turns.
  struct Quad {
    Vec2 q[2][2]{};
    double orientation = 0.0;
  };
  // One assignment of target lines 1-4 to the image lines and its cost.
  struct Assignment {
    double cost = 0.0;
    double previous_angle_deg = 180.0;  // from the previous pose's rotation (180 without one)
    std::array<int, 4> line_index{};
    std::array<Point2d, 4> corners{};
  };

  bool SplitIntoGroups(const std::array<int, 4>& idx, Groups* groups, std::string* message) const;
  bool FindCorners(const Groups& groups, Quad* quad, std::string* message) const;
  int Assign(const Groups& groups, const Quad& quad, std::array<Assignment, 4>* kept) const;
  SubsetResult Choose(const std::array<Assignment, 4>& kept, int n_kept) const;

  double GroupAngle(int a, int b, int c, int d) const {
    const LineParams* l[4] = {&lines_[a].line, &lines_[b].line, &lines_[c].line, &lines_[d].line};
    return std::min(std::min(AngleBetween(*l[0], *l[2]), AngleBetween(*l[0], *l[3])),
                    std::min(AngleBetween(*l[1], *l[2]), AngleBetween(*l[1], *l[3])));
  }
  // Homography board -> pixels of one assignment, its cost (infinite if invalid).
  double Cost(const Mat3& h, const std::array<int, 4>& image_line_of_target) const;
  // Angle between the rotation of the board -> pixels homography h and the previous pose's.
  double PreviousAngleDeg(const Mat3& h) const;

  const std::vector<DetectedLine>& lines_;
  const HashTarget& target_;
  const PoseOptions& options_;
  const vpRotationMatrix* previous_cRo_;
  Mat3 k_inv_{};
};

double Identifier::PreviousAngleDeg(const Mat3& h) const {
  // K^-1 H = s [r1 r2 t]; the sign that puts the board in front of the camera (t_z > 0).
  const Mat3 g = Multiply(k_inv_, h);
  const double sign = g[8] >= 0.0 ? 1.0 : -1.0;
  double r1[3] = {sign * g[0], sign * g[3], sign * g[6]};
  double r2[3] = {sign * g[1], sign * g[4], sign * g[7]};
  const double n1 = std::sqrt(r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2]);
  const double n2 = std::sqrt(r2[0] * r2[0] + r2[1] * r2[1] + r2[2] * r2[2]);
  if (!(n1 > 0.0 && n2 > 0.0)) return 180.0;
  for (int i = 0; i < 3; ++i) {
    r1[i] /= n1;
    r2[i] /= n2;
  }
  const double r3[3] = {r1[1] * r2[2] - r1[2] * r2[1], r1[2] * r2[0] - r1[0] * r2[2],
                        r1[0] * r2[1] - r1[1] * r2[0]};
  const vpRotationMatrix& p = *previous_cRo_;
  // trace(Pᵀ R) over the columns r1, r2, r3 of R.
  double trace = 0.0;
  for (int i = 0; i < 3; ++i) trace += p[i][0] * r1[i] + p[i][1] * r2[i] + p[i][2] * r3[i];
  const double cosine = 0.5 * (trace - 1.0);
  return std::isfinite(cosine) ? std::acos(std::clamp(cosine, -1.0, 1.0)) * kDegPerRad : 180.0;
}

double Identifier::Cost(const Mat3& h, const std::array<int, 4>& image_line_of_target) const {
  // Orthonormality of the first two columns of K^-1 H.
  const Mat3 g = Multiply(k_inv_, h);
  const double g1[3] = {g[0], g[3], g[6]}, g2[3] = {g[1], g[4], g[7]};
  const double n1 = std::sqrt(g1[0] * g1[0] + g1[1] * g1[1] + g1[2] * g1[2]);
  const double n2 = std::sqrt(g2[0] * g2[0] + g2[1] * g2[1] + g2[2] * g2[2]);
  if (!(n1 > 0.0 && n2 > 0.0) || !std::isfinite(n1) || !std::isfinite(n2)) return kInf;
  const double log_ratio = std::log(n1 / n2);
  const double cosine = (g1[0] * g2[0] + g1[1] * g2[1] + g1[2] * g2[2]) / (n1 * n2);
  const double s_o = options_.ortho_sigma;
  double cost = (log_ratio * log_ratio + cosine * cosine) / (s_o * s_o);

  // Apparent widths.
  std::array<double, 4> r{};
  double mean = 0.0;
  const Mat3 h_inv = Adjugate(h);
  for (int k = 0; k < 4; ++k) {
    const DetectedLine& line = lines_[image_line_of_target[k]];
    if (!(line.width_px > 0.0)) return cost;  // a width unknown: geometry only
    // Middle of the visible part; the line's two corners if the ends are unset.
    Vec2 p{0.5 * (line.end_a.u + line.end_b.u), 0.5 * (line.end_a.v + line.end_b.v)};
    if (std::hypot(line.end_a.u - line.end_b.u, line.end_a.v - line.end_b.v) < 1.0) {
      const int before = (k + 3) % 4;  // corner[k-1] and corner[k] lie on line k
      Vec2 a, b;
      const Vec2& ca = target_.corner[before];
      const Vec2& cb = target_.corner[k];
      if (!Apply(h, ca.x, ca.y, &a) || !Apply(h, cb.x, cb.y, &b)) return kInf;
      p = {0.5 * (a.x + b.x), 0.5 * (a.y + b.y)};
    }
    Vec2 on_board;
    if (!Apply(h_inv, p.x, p.y, &on_board)) return kInf;
    const double half = 0.5 * target_.width_m[k];
    const Vec2& n = target_.normal[k];
    Vec2 q_plus, q_minus;
    if (!Apply(h, on_board.x + half * n.x, on_board.y + half * n.y, &q_plus) ||
        !Apply(h, on_board.x - half * n.x, on_board.y - half * n.y, &q_minus)) {
      return kInf;
    }
    const double c = std::cos(line.line.theta_rad), s = std::sin(line.line.theta_rad);
    const double predicted = std::fabs(c * (q_plus.x - q_minus.x) + s * (q_plus.y - q_minus.y));
    if (!(predicted > 0.0) || !std::isfinite(predicted)) return kInf;
    r[k] = std::log(line.width_px / predicted);
    mean += 0.25 * r[k];
  }
  const double s_w = options_.width_sigma;
  for (int k = 0; k < 4; ++k) cost += (r[k] - mean) * (r[k] - mean) / (s_w * s_w);
  return cost;
}

// Step 1: the split of the four lines into two groups with the largest angle between groups.
bool Identifier::SplitIntoGroups(const std::array<int, 4>& idx, Groups* groups,
                                 std::string* message) const {
  static constexpr int kSplits[3][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}};
  int best_split = 0;
  double best_angle = -1.0;
  for (int s = 0; s < 3; ++s) {
    const double angle =
        GroupAngle(idx[kSplits[s][0]], idx[kSplits[s][1]], idx[kSplits[s][2]], idx[kSplits[s][3]]);
    if (angle > best_angle) {
      best_angle = angle;
      best_split = s;
    }
  }
  groups->g = {idx[kSplits[best_split][0]], idx[kSplits[best_split][1]]};
  groups->h = {idx[kSplits[best_split][2]], idx[kSplits[best_split][3]]};
  if (best_angle * kDegPerRad < options_.min_group_angle_deg) {
    std::ostringstream text;
    text << "the lines do not form two groups of crossing lines: lines of different groups "
            "meet at "
         << best_angle * kDegPerRad
         << " deg < min_group_angle_deg = " << options_.min_group_angle_deg;
    *message = text.str();
    return false;
  }
  return true;
}

// Step 2: the corners q[i][j] = G_i ∩ H_j, near the image, a convex quadrilateral; its
// orientation (the sign of its turns).
bool Identifier::FindCorners(const Groups& groups, Quad* quad, std::string* message) const {
  const Lens& camera = options_.camera;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      Point2d p;
      if (!Intersect(lines_[groups.g[i]].line, lines_[groups.h[j]].line, &p, 1e-6)) {
        *message = "two lines of different groups are parallel";
        return false;
      }
      quad->q[i][j] = {p.u, p.v};
      double x = 0.0, y = 0.0;
      pose_internal::PixelToMetre(camera, options_.lines_undistorted, p, &x, &y);
      const double radius = std::hypot(x, y);
      double outside = 0.0;
      if (options_.image_width > 0 && options_.image_height > 0) {
        outside = std::max(
            {0.0, -p.u, p.u - (options_.image_width - 1), -p.v, p.v - (options_.image_height - 1)});
      }
      if (!(radius <= options_.max_intersection_radius) || outside > options_.max_outside_px) {
        std::ostringstream text;
        text << "the intersection of lines " << groups.g[i] << " and " << groups.h[j]
             << " lies too far away: (" << p.u << ", " << p.v << ") px, " << outside
             << " px outside the image (max_outside_px = " << options_.max_outside_px
             << "), radius " << radius
             << " (max_intersection_radius = " << options_.max_intersection_radius << ")";
        *message = text.str();
        return false;
      }
    }
  }
  const Vec2 corners[4] = {quad->q[0][0], quad->q[1][0], quad->q[1][1], quad->q[0][1]};
  for (int c = 0; c < 4; ++c) {
    const Vec2 e1 = Minus(corners[(c + 1) % 4], corners[c]);
    const Vec2 e2 = Minus(corners[(c + 2) % 4], corners[(c + 1) % 4]);
    const double turn = Cross(e1, e2);
    const double side = std::hypot(e1.x, e1.y);
    if (side < options_.min_side_px || turn == 0.0 ||
        (c > 0 && (turn > 0.0) != (quad->orientation > 0.0))) {
      std::ostringstream text;
      text << "the four intersections do not form a convex quadrilateral with sides of at "
              "least min_side_px = "
           << options_.min_side_px << " px";
      *message = text.str();
      return false;
    }
    if (c == 0) quad->orientation = turn;
  }
  return true;
}

// Step 3: the orientation-preserving assignments of the target's lines to the groups (four
// of the eight; a reflection would put the camera behind the board), each with its cost.
int Identifier::Assign(const Groups& groups, const Quad& quad,
                       std::array<Assignment, 4>* kept) const {
  const Mat3 h0 = SquareToQuad(quad.q[0][0], quad.q[1][0], quad.q[1][1], quad.q[0][1]);
  static constexpr int kPairs[2][2] = {{0, 2}, {1, 3}};  // target lines 1, 3 and 2, 4
  // Board corner of target lines a and b (adjacent indices mod 4).
  const auto corner_of = [](int a, int b) {
    return ((a + 1) % 4 == b) ? a : b;  // corner[k] = lines[k] ∩ lines[k+1]
  };
  int n_kept = 0;
  for (int swap = 0; swap < 2; ++swap) {
    for (int flip_g = 0; flip_g < 2; ++flip_g) {
      for (int flip_h = 0; flip_h < 2; ++flip_h) {
        int target_g[2], target_h[2];  // target line of G_i, H_j
        for (int i = 0; i < 2; ++i) {
          target_g[i] = kPairs[swap][i ^ flip_g];
          target_h[i] = kPairs[1 - swap][i ^ flip_h];
        }
        const Vec2& o00 = target_.corner[corner_of(target_g[0], target_h[0])];
        const Vec2& o10 = target_.corner[corner_of(target_g[1], target_h[0])];
        const Vec2& o01 = target_.corner[corner_of(target_g[0], target_h[1])];
        const Vec2 e1 = Minus(o10, o00), e2 = Minus(o01, o00);
        const double det = Cross(e1, e2);
        if (det * quad.orientation <= 0.0) continue;  // a reflection: camera behind the board
        // Board -> square: (s, t) = M^-1 (X - o00), M = [e1 e2].
        const Mat3 board_to_square = {e2.y / det,  -e2.x / det, (e2.x * o00.y - e2.y * o00.x) / det,
                                      -e1.y / det, e1.x / det,  (e1.y * o00.x - e1.x * o00.y) / det,
                                      0.0,         0.0,         1.0};
        const Mat3 h = Multiply(h0, board_to_square);
        Assignment& a = (*kept)[n_kept++];
        for (int i = 0; i < 2; ++i) {
          a.line_index[target_g[i]] = groups.g[i];
          a.line_index[target_h[i]] = groups.h[i];
        }
        for (int i = 0; i < 2; ++i)
          for (int j = 0; j < 2; ++j)
            a.corners[corner_of(target_g[i], target_h[j])] =
                Point2d{quad.q[i][j].x, quad.q[i][j].y};
        a.cost = Cost(h, a.line_index);
        a.previous_angle_deg = previous_cRo_ != nullptr && options_.previous_max_deg > 0.0
                                   ? PreviousAngleDeg(h)
                                   : 180.0;
      }
    }
  }
  return n_kept;
}

// Step 4: a clear winner among the assignments, or the one that agrees with the previous pose.
SubsetResult Identifier::Choose(const std::array<Assignment, 4>& kept, int n_kept) const {
  SubsetResult result;
  int best = -1, second = -1;
  for (int k = 0; k < n_kept; ++k) {
    if (best < 0 || kept[k].cost < kept[best].cost) {
      second = best;
      best = k;
    } else if (second < 0 || kept[k].cost < kept[second].cost) {
      second = k;
    }
  }
  if (best < 0 || !std::isfinite(kept[best].cost)) {
    result.message = "no assignment of the target lines fits the intersections";
    result.status = PoseStatus::kNotIdentifiable;
    return result;
  }
  // Continuity (PoseOptions::previous_max_deg): the frame's winner turned away from the
  // previous pose loses to the assignment that agrees with it, unless that one's own cost
  // rules it out.
  const double keep_deg = options_.previous_max_deg;
  if (previous_cRo_ != nullptr && keep_deg > 0.0 && kept[best].previous_angle_deg > keep_deg) {
    int agreeing = -1;
    for (int k = 0; k < n_kept; ++k) {
      if (kept[k].previous_angle_deg <= keep_deg &&
          kept[k].cost <= options_.max_identification_cost &&
          (agreeing < 0 || kept[k].cost < kept[agreeing].cost)) {
        agreeing = k;
      }
    }
    if (agreeing >= 0) {
      result.line_index = kept[agreeing].line_index;
      result.corners_px = kept[agreeing].corners;
      result.cost = kept[agreeing].cost;
      result.margin = kInf;  // chosen by the previous pose, not by its margin
      result.status = PoseStatus::kOk;
      return result;
    }
  }
  result.line_index = kept[best].line_index;
  result.corners_px = kept[best].corners;
  result.cost = kept[best].cost;
  result.margin = second >= 0 ? kept[second].cost - kept[best].cost : kInf;
  if (result.cost > options_.max_identification_cost ||
      result.margin < options_.min_identification_margin) {
    std::ostringstream message;
    message << "lines 1-4 not identifiable: best assignment cost " << result.cost
            << " (max_identification_cost = " << options_.max_identification_cost << "), runner-up "
            << result.margin
            << " higher (min_identification_margin = " << options_.min_identification_margin << ")";
    result.message = message.str();
    result.status = PoseStatus::kNotIdentifiable;
    return result;
  }
  result.status = PoseStatus::kOk;
  return result;
}

SubsetResult Identifier::Evaluate(const std::array<int, 4>& idx) const {
  SubsetResult result;
  Groups groups;
  if (!SplitIntoGroups(idx, &groups, &result.message)) return result;
  Quad quad;
  if (!FindCorners(groups, &quad, &result.message)) return result;
  std::array<Assignment, 4> kept{};
  const int n_kept = Assign(groups, quad, &kept);
  return Choose(kept, n_kept);
}

}  // namespace

namespace pose_internal {

HashTarget HashTargetFrom(const LineTarget& target) {
  if (target.lines.size() != 4) {
    throw std::invalid_argument("pose target '" + target.name +
                                "': " + std::to_string(target.lines.size()) +
                                " lines, a '#' target needs 4");
  }
  HashTarget hash;
  for (int k = 0; k < 4; ++k) {
    const TargetLine& line = target.lines[k];
    const double dx = line.x2_m - line.x1_m, dy = line.y2_m - line.y1_m;
    const double length = std::hypot(dx, dy);
    if (!(length > 0.0) || !(line.width_m > 0.0)) {
      throw std::invalid_argument("pose target '" + target.name + "': line " +
                                  std::to_string(k + 1) + " has no length or no width");
    }
    hash.direction[k] = {dx / length, dy / length};
    hash.normal[k] = {-dy / length, dx / length};
    hash.width_m[k] = line.width_m;
  }
  const double kParallel = std::sin(1e-3), kCrossing = std::sin(10.0 / kDegPerRad);
  if (std::fabs(Cross(hash.direction[0], hash.direction[2])) > kParallel ||
      std::fabs(Cross(hash.direction[1], hash.direction[3])) > kParallel ||
      std::fabs(Cross(hash.direction[0], hash.direction[1])) < kCrossing) {
    throw std::invalid_argument("pose target '" + target.name +
                                "' is not a '#': lines 1 and 3, and 2 and 4, must be parallel, "
                                "lines 1 and 2 must cross at 10 deg or more");
  }
  for (int k = 0; k < 4; ++k) {
    const TargetLine& a = target.lines[k];
    const TargetLine& b = target.lines[(k + 1) % 4];
    const Vec2 da = hash.direction[k], db = hash.direction[(k + 1) % 4];
    // a1 + s da = b1 + t db  ->  s = cross(b1 - a1, db) / cross(da, db).
    const Vec2 w{b.x1_m - a.x1_m, b.y1_m - a.y1_m};
    const double s = Cross(w, db) / Cross(da, db);
    hash.corner[k] = {a.x1_m + s * da.x, a.y1_m + s * da.y};
  }
  if (std::hypot(hash.corner[0].x - hash.corner[2].x, hash.corner[0].y - hash.corner[2].y) <= 0.0) {
    throw std::invalid_argument("pose target '" + target.name + "': its corners coincide");
  }
  return hash;
}

void PixelToMetre(const Lens& camera, bool undistorted, const Point2d& p, double* x, double* y) {
  if (undistorted) {
    *x = (p.u - camera.u0()) / camera.px();
    *y = (p.v - camera.v0()) / camera.py();
  } else {
    const Point2d ideal = camera.Normalised(p.u, p.v);
    *x = ideal.u;
    *y = ideal.v;
  }
}

PoseResult Identify(const std::vector<DetectedLine>& lines, const HashTarget& target,
                    const PoseOptions& options, const vpRotationMatrix* previous_cRo) {
  PoseResult result;
  if (lines.size() < 4) {
    result.status = PoseStatus::kNotEnoughLines;
    result.message = "only " + std::to_string(lines.size()) + " lines detected, the target needs 4";
    return result;
  }
  const Identifier identifier(lines, target, options, previous_cRo);
  SubsetResult chosen = identifier.Evaluate({{0, 1, 2, 3}});
  if (chosen.status != PoseStatus::kOk) {
    const int n =
        static_cast<int>(std::min<std::size_t>(lines.size(), options.max_candidate_lines));
    SubsetResult best_other;
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b)
        for (int c = b + 1; c < n; ++c)
          for (int d = c + 1; d < n; ++d) {
            if (d == 3) continue;  // the first four, done above
            SubsetResult other = identifier.Evaluate({{a, b, c, d}});
            if (other.status == PoseStatus::kOk && other.cost < best_other.cost) {
              best_other = std::move(other);
            }
          }
    if (best_other.status == PoseStatus::kOk) chosen = std::move(best_other);
  }
  result.status = chosen.status;
  result.message = std::move(chosen.message);
  result.line_index = chosen.line_index;
  result.corners_px = chosen.corners_px;
  result.identification_cost = chosen.cost;
  result.identification_margin = chosen.margin;
  return result;
}

}  // namespace pose_internal

std::string ToString(PoseStatus status) {
  switch (status) {
    case PoseStatus::kOk:
      return "ok";
    case PoseStatus::kNotEnoughLines:
      return "not-enough-lines";
    case PoseStatus::kNotIdentifiable:
      return "not-identifiable";
    case PoseStatus::kDegenerate:
      return "degenerate";
  }
  return "unknown";
}

std::string ToString(PoseMethod method) {
  switch (method) {
    case PoseMethod::kNone:
      return "none";
    case PoseMethod::kDementhon:
      return "dementhon";
    case PoseMethod::kLagrange:
      return "lagrange";
    case PoseMethod::kPrevious:
      return "previous";
    case PoseMethod::kHomography:
      return "homography";
    case PoseMethod::kStripes:
      return "stripes";
  }
  return "unknown";
}

PoseOptions PoseOptions::ScaledBy(double scale) const {
  RequireOption(scale > 0.0 && scale <= 100.0, "PoseOptions::ScaledBy scale", scale,
                "0 < scale <= 100");
  PoseOptions scaled = *this;
  scaled.max_outside_px = max_outside_px * scale;
  scaled.min_side_px = min_side_px * scale;
  scaled.max_residual_px = max_residual_px * scale;
  return scaled;
}

void PoseOptions::Check() const {
  CheckPerspectiveCamera(camera, "PoseOptions::camera");
  RequireOption(max_candidate_lines >= 4 && max_candidate_lines <= 12,
                "PoseOptions::max_candidate_lines", max_candidate_lines,
                "4 <= max_candidate_lines <= 12");
  RequireOption(min_group_angle_deg > 0.0 && min_group_angle_deg < 90.0,
                "PoseOptions::min_group_angle_deg", min_group_angle_deg,
                "0 < min_group_angle_deg < 90");
  RequireOption(image_width >= 0 && image_width <= 100000, "PoseOptions::image_width", image_width,
                "0 <= image_width <= 100000");
  RequireOption(image_height >= 0 && image_height <= 100000, "PoseOptions::image_height",
                image_height, "0 <= image_height <= 100000");
  RequireOption((image_width == 0) == (image_height == 0), "PoseOptions::image_height",
                image_height, "image_width and image_height both 0 (unknown) or both > 0");
  RequireOption(InRange(max_outside_px, 0.0, 1e6), "PoseOptions::max_outside_px", max_outside_px,
                "0 <= max_outside_px <= 1e6");
  RequireOption(max_intersection_radius > 0.0 && max_intersection_radius <= 100.0,
                "PoseOptions::max_intersection_radius", max_intersection_radius,
                "0 < max_intersection_radius <= 100");
  RequireOption(InRange(min_side_px, 0.0, 1e6), "PoseOptions::min_side_px", min_side_px,
                "0 <= min_side_px <= 1e6");
  RequireOption(ortho_sigma > 0.0 && ortho_sigma <= 10.0, "PoseOptions::ortho_sigma", ortho_sigma,
                "0 < ortho_sigma <= 10");
  RequireOption(width_sigma > 0.0 && width_sigma <= 10.0, "PoseOptions::width_sigma", width_sigma,
                "0 < width_sigma <= 10");
  RequireOption(max_identification_cost > 0.0 && max_identification_cost <= 1e9,
                "PoseOptions::max_identification_cost", max_identification_cost,
                "0 < max_identification_cost <= 1e9");
  RequireOption(InRange(min_identification_margin, 0.0, 1e9),
                "PoseOptions::min_identification_margin", min_identification_margin,
                "0 <= min_identification_margin <= 1e9");
  RequireOption(max_residual_px > 0.0 && max_residual_px <= 1000.0, "PoseOptions::max_residual_px",
                max_residual_px, "0 < max_residual_px <= 1000");
  RequireOption(InRange(previous_tolerance_px, 0.0, 1000.0), "PoseOptions::previous_tolerance_px",
                previous_tolerance_px, "0 <= previous_tolerance_px <= 1000");
  RequireOption(min_depth_m > 0.0 && min_depth_m <= 1e3, "PoseOptions::min_depth_m", min_depth_m,
                "0 < min_depth_m <= 1e3");
  RequireOption(InRange(dementhon_above_px, 0.0, 1000.0), "PoseOptions::dementhon_above_px",
                dementhon_above_px, "0 <= dementhon_above_px <= 1000");
  RequireOption(InRange(previous_accept_px, 0.0, 1000.0), "PoseOptions::previous_accept_px",
                previous_accept_px, "0 <= previous_accept_px <= 1000");
  RequireOption(InRange(homography_accept_px, 0.0, 1000.0), "PoseOptions::homography_accept_px",
                homography_accept_px, "0 <= homography_accept_px <= 1000");
  RequireOption(InRange(previous_max_deg, 0.0, 180.0), "PoseOptions::previous_max_deg",
                previous_max_deg, "0 <= previous_max_deg <= 180");
  RequireOption(vvs_max_iterations >= 1 && vvs_max_iterations <= 1000,
                "PoseOptions::vvs_max_iterations", vvs_max_iterations,
                "1 <= vvs_max_iterations <= 1000");
}

PoseResult IdentifyTargetLines(const std::vector<DetectedLine>& lines, const LineTarget& target,
                               const PoseOptions& options) {
  options.Check();
  return pose_internal::Identify(lines, pose_internal::HashTargetFrom(target), options, nullptr);
}

}  // namespace oal
