#include "eval/lines/opencv_methods.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/fast_line_detector.hpp>
#include <vector>

#include "base/angles.h"

namespace oal {
namespace {

// Drops lines within `angle_deg` and `distance_px` of a better (earlier) line.
std::vector<LineParams> Deduplicated(const std::vector<LineParams>& lines, double angle_deg,
                                     double distance_px, const Point2d& centre) {
  std::vector<LineParams> kept;
  for (const LineParams& line : lines) {
    const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](const LineParams& k) {
      return AngleBetween(k, line) * kDegPerRad <= angle_deg &&
             DistanceAt(k, line, centre) <= distance_px;
    });
    if (!duplicate) kept.push_back(line);
  }
  return kept;
}

// Pairs the edge lines of stripes into centre lines (docs/COMPARE.md).
std::vector<LineParams> PairedEdges(const std::vector<LineParams>& lines, double max_width_px,
                                    const Point2d& centre) {
  constexpr double kPairAngleDeg = 2.0, kMinWidthPx = 1.0;
  std::vector<bool> used(lines.size(), false);
  std::vector<LineParams> out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (used[i]) continue;
    used[i] = true;
    std::size_t best = lines.size();
    double best_distance = max_width_px;
    for (std::size_t j = i + 1; j < lines.size(); ++j) {
      if (used[j] || AngleBetween(lines[i], lines[j]) * kDegPerRad > kPairAngleDeg) continue;
      const double distance = DistanceAt(lines[i], lines[j], centre);
      if (distance >= kMinWidthPx && distance <= best_distance) {
        best = j;
        best_distance = distance;
      }
    }
    if (best == lines.size()) {
      out.push_back(lines[i]);
    } else {
      used[best] = true;
      out.push_back(Midline(lines[i], lines[best], centre));
    }
  }
  return out;
}

// Segments (x1, y1, x2, y2) merged into lines, ranked by total length (docs/COMPARE.md).
std::vector<LineParams> MergedSegments(const std::vector<cv::Vec4f>& segments) {
  constexpr double kAngleDeg = 1.5, kDistancePx = 1.5;
  struct Cluster {
    LineParams line;
    double length = 0.0;
    double sw = 0.0, su = 0.0, sv = 0.0, suu = 0.0, suv = 0.0, svv = 0.0;  // weighted moments
    void Add(const Point2d& p, double w) {
      sw += w;
      su += w * p.u;
      sv += w * p.v;
      suu += w * p.u * p.u;
      suv += w * p.u * p.v;
      svv += w * p.v * p.v;
    }
    void Refit() {
      const double mu = su / sw, mv = sv / sw;
      const double cuu = suu / sw - mu * mu, cuv = suv / sw - mu * mv, cvv = svv / sw - mv * mv;
      // The normal is the eigenvector of the smaller eigenvalue of the covariance.
      const double direction = 0.5 * std::atan2(2.0 * cuv, cuu - cvv);
      const double theta = direction + kPi / 2;
      line = Normalized(mu * std::cos(theta) + mv * std::sin(theta), theta);
    }
  };
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const cv::Vec4f& s = segments[i];
    order.emplace_back(std::hypot(s[2] - s[0], s[3] - s[1]), i);
  }
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a > b; });
  std::vector<Cluster> clusters;
  for (const auto& [length, index] : order) {
    const cv::Vec4f& s = segments[index];
    const Point2d a{s[0], s[1]}, b{s[2], s[3]};
    if (length < 1e-6) continue;
    const LineParams own = LineThrough(a, b);
    Cluster* home = nullptr;
    for (Cluster& cluster : clusters) {
      if (AngleBetween(cluster.line, own) * kDegPerRad <= kAngleDeg &&
          std::fabs(cluster.line.SignedDistance(a.u, a.v)) <= kDistancePx &&
          std::fabs(cluster.line.SignedDistance(b.u, b.v)) <= kDistancePx) {
        home = &cluster;
        break;
      }
    }
    if (home == nullptr) {
      clusters.emplace_back();
      home = &clusters.back();
      home->line = own;
    }
    home->Add(a, 0.5 * length);
    home->Add(b, 0.5 * length);
    home->length += length;
    home->Refit();
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const Cluster& x, const Cluster& y) { return x.length > y.length; });
  std::vector<LineParams> lines;
  for (const Cluster& cluster : clusters) lines.push_back(cluster.line);
  return lines;
}

cv::Mat MatOf(const vpImage<unsigned char>& image) {
  return cv::Mat(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()), CV_8UC1,
                 const_cast<unsigned char*>(image.bitmap));
}

// The OpenCV methods, one class: they share the Canny edges, the segment merging and the
// edge pairing.
class OpenCvMethod : public LineMethod {
 public:
  using Kind = OpenCvLineDetector;

  OpenCvMethod(Kind kind, bool stripes, Polarity polarity, double max_stripe_width_px,
               const DetectorOptions& detector)
      : kind_(kind),
        stripes_(stripes),
        polarity_(polarity),
        max_stripe_width_px_(max_stripe_width_px),
        duplicate_angle_deg_(detector.duplicate_angle_deg),
        duplicate_r_px_(detector.duplicate_r_px) {
    if (kind_ == Kind::kLsd) lsd_ = cv::createLineSegmentDetector(cv::LSD_REFINE_STD);
    if (kind_ == Kind::kFld) fld_ = cv::ximgproc::createFastLineDetector();
  }

  std::string Name() const override {
    switch (kind_) {
      case Kind::kHoughCanny:
        return "HoughLines (Canny)";
      case Kind::kHoughOtsu:
        return "HoughLines (Otsu)";
      case Kind::kHoughP:
        return "HoughLinesP (Canny)";
      case Kind::kLsd:
        return "LSD";
      case Kind::kFld:
        return "FastLineDetector";
    }
    return "?";
  }

  void Process(const vpImage<unsigned char>& image, std::vector<LineParams>* lines) override {
    const cv::Mat view = MatOf(image);
    const Point2d centre{0.5 * (view.cols - 1), 0.5 * (view.rows - 1)};
    const int size = std::min(view.cols, view.rows);
    const int hough_votes = std::max(20, size / 4);
    std::vector<LineParams> found;
    switch (kind_) {
      case Kind::kHoughCanny: {
        CannyEdges(view);
        HoughPeaks(edges_, hough_votes, &found);
        found = Deduplicated(found, 1.0, 1.5, centre);
        break;
      }
      case Kind::kHoughOtsu: {
        const int type =
            polarity_ == Polarity::kLightLines ? cv::THRESH_BINARY : cv::THRESH_BINARY_INV;
        cv::threshold(view, binary_, 0, 255, type | cv::THRESH_OTSU);
        if (polarity_ == Polarity::kEdges) {  // the boundary of the binary image votes
          cv::erode(binary_, eroded_, cv::Mat());
          cv::subtract(binary_, eroded_, binary_);
        }
        HoughPeaks(binary_, hough_votes, &found);
        *lines = Deduplicated(found, duplicate_angle_deg_, duplicate_r_px_, centre);
        return;  // centre lines (stripes) or edges already: nothing to pair
      }
      case Kind::kHoughP: {
        CannyEdges(view);
        segments_.clear();
        std::vector<cv::Vec4i> segments;
        cv::HoughLinesP(edges_, segments, 1.0, CV_PI / 360.0, std::max(10, size / 8),
                        std::max(10.0, size / 10.0), 5.0);
        for (const cv::Vec4i& s : segments) segments_.emplace_back(s[0], s[1], s[2], s[3]);
        found = MergedSegments(segments_);
        break;
      }
      case Kind::kLsd:
        segments_.clear();
        lsd_->detect(view, segments_);
        found = MergedSegments(segments_);
        break;
      case Kind::kFld:
        segments_.clear();
        fld_->detect(view, segments_);
        found = MergedSegments(segments_);
        break;
    }
    *lines = stripes_ ? PairedEdges(found, max_stripe_width_px_, centre) : std::move(found);
  }

 private:
  void CannyEdges(const cv::Mat& view) {
    cv::GaussianBlur(view, blurred_, cv::Size(5, 5), 1.2);
    cv::Canny(blurred_, edges_, 50, 150);
  }
  static void HoughPeaks(const cv::Mat& binary, int votes, std::vector<LineParams>* lines) {
    std::vector<cv::Vec2f> peaks;  // sorted by votes, best first
    cv::HoughLines(binary, peaks, 1.0, CV_PI / 360.0, votes);
    lines->clear();
    for (const cv::Vec2f& peak : peaks) lines->push_back(Normalized(peak[0], peak[1]));
  }

  Kind kind_;
  bool stripes_;
  Polarity polarity_;
  double max_stripe_width_px_;
  double duplicate_angle_deg_, duplicate_r_px_;
  cv::Ptr<cv::LineSegmentDetector> lsd_;
  cv::Ptr<cv::ximgproc::FastLineDetector> fld_;
  cv::Mat blurred_, edges_, binary_, eroded_;
  std::vector<cv::Vec4f> segments_;
};

}  // namespace

std::unique_ptr<LineMethod> MakeOpenCvMethod(OpenCvLineDetector kind, bool stripes,
                                             Polarity polarity, double max_stripe_width_px,
                                             const DetectorOptions& detector) {
  return std::make_unique<OpenCvMethod>(kind, stripes, polarity, max_stripe_width_px, detector);
}

}  // namespace oal
