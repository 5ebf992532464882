#include "eval/rendered/apriltag_method.h"

#include <visp3/detection/vpDetectorAprilTag.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "base/clock.h"
#include "base/format.h"
#include "detector/lens.h"

namespace oal {
namespace {

// The tag's black square is 8 modules (border and 6 x 6 bits), the picture 9.5: a white border
// of 3/4 of a module on each side. Texels of 1/4 module.
constexpr int kBlackModules = 8;
constexpr double kPictureModules = 9.5;
constexpr int kTexelsPerModule = 4;

// The sheet's pose from the tag's in ViSP's frame aligned with the camera (z into the tag, x
// and y along the tag's corners 3 -> 2 and 3 -> 0 as the AprilTag library orders them). OpenCV
// draws the tag rotated by 180 degrees from the library's upright tag: its corner 0 is the
// picture's top right, 1 its top left, so the sheet's x and y are the aligned frame's -x and -y.
vpHomogeneousMatrix SheetFromTag() {
  vpHomogeneousMatrix tMo;
  tMo[0][0] = -1.0;
  tMo[1][1] = -1.0;
  return tMo;
}

// `camera` in the AprilTag library's pixels, whose centres lie at (i + 1/2, j + 1/2) where ours
// and ViSP's lie at (i, j) (its bilinear sampling subtracts 1/2 from a position to index the
// pixels): the principal point moved by half a pixel right and down. ViSP 3.5's getPose hands
// the library's corners to a camera in ViSP's pixels, half a pixel off in u and v; in the
// library's pixels u - u0 is the same as in ours, so the pose (homography, then the corners
// undistorted with kdu) is that of the corners where they are. A distorted lens's frames are
// resampled to a pinhole camera first (LensUndistortion), so the pinhole's is all it needs.
vpCameraParameters InLibraryPixels(const Lens& pinhole) {
  return vpCameraParameters(pinhole.px(), pinhole.py(), pinhole.u0() + 0.5, pinhole.v0() + 0.5);
}

double PolygonArea(const std::vector<vpImagePoint>& polygon) {
  double twice = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const vpImagePoint& a = polygon[i];
    const vpImagePoint& b = polygon[(i + 1) % polygon.size()];
    twice += a.get_u() * b.get_v() - b.get_u() * a.get_v();
  }
  return 0.5 * std::fabs(twice);
}

// The frames of a camera with ViSP's kdu lens, resampled as an ideal pinhole camera with the
// same px, py would see them: the canvas covers the whole frame (its principal point moved by
// as much as the frame's corners reach past the top-left), each canvas pixel bilinear in the
// frame at the distorted pixel of its ray (DistortedPixel: kdu exactly), mid-grey where the
// frame has none.
class LensUndistortion {
 public:
  LensUndistortion(const Lens& camera, int width, int height) {
    const double px = camera.px(), py = camera.py();
    double min_u = 1e300, min_v = 1e300, max_u = -1e300, max_v = -1e300;
    const auto grow = [&](double u, double v) {
      const Point2d ideal = camera.Normalised(u, v);
      const double x = ideal.u, y = ideal.v;
      min_u = std::min(min_u, camera.u0() + px * x);
      max_u = std::max(max_u, camera.u0() + px * x);
      min_v = std::min(min_v, camera.v0() + py * y);
      max_v = std::max(max_v, camera.v0() + py * y);
    };
    for (int u = 0; u < width; ++u) {
      grow(u, 0.0);
      grow(u, height - 1.0);
    }
    for (int v = 0; v < height; ++v) {
      grow(0.0, v);
      grow(width - 1.0, v);
    }
    const double left = std::floor(min_u), top = std::floor(min_v);
    const int cols = static_cast<int>(std::ceil(max_u) - left) + 1;
    const int rows = static_cast<int>(std::ceil(max_v) - top) + 1;
    pinhole_ = Lens::Pinhole(px, py, camera.u0() - left, camera.v0() - top);
    cv::Mat1f map_u(rows, cols), map_v(rows, cols);
    for (int j = 0; j < rows; ++j) {
      for (int i = 0; i < cols; ++i) {
        const Point2d p = camera.Pixel((i - pinhole_.u0()) / px, (j - pinhole_.v0()) / py);
        const bool seen = std::isfinite(p.u) && std::isfinite(p.v);
        map_u(j, i) = seen ? static_cast<float>(p.u) : -10.0f;
        map_v(j, i) = seen ? static_cast<float>(p.v) : -10.0f;
      }
    }
    cv::convertMaps(map_u, map_v, map_fixed_, map_fraction_, CV_16SC2);
    canvas_.resize(static_cast<unsigned>(rows), static_cast<unsigned>(cols));
  }

  /// The pinhole camera of the canvas (ViSP's pixels).
  const Lens& pinhole() const { return pinhole_; }

  const vpImage<unsigned char>& Undistort(const vpImage<unsigned char>& frame) {
    const cv::Mat in(static_cast<int>(frame.getHeight()), static_cast<int>(frame.getWidth()), CV_8U,
                     frame.bitmap);
    cv::Mat out(static_cast<int>(canvas_.getHeight()), static_cast<int>(canvas_.getWidth()), CV_8U,
                canvas_.bitmap);
    cv::remap(in, out, map_fixed_, map_fraction_, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
              cv::Scalar(128));
    return canvas_;
  }

 private:
  Lens pinhole_;
  cv::Mat map_fixed_, map_fraction_;
  vpImage<unsigned char> canvas_;
};

class AprilTagMethod : public MarkerMethod {
 public:
  AprilTagMethod(const LineTarget& sheet, const Lens& camera, int width, int height)
      : tag_size_m_(AprilTagBlackSide(sheet)),
        detector_(vpDetectorAprilTag::TAG_36h11, vpDetectorAprilTag::HOMOGRAPHY_VIRTUAL_VS) {
    if (camera.distorted()) {
      undistortion_ = std::make_unique<LensUndistortion>(camera, width, height);
      camera_ = InLibraryPixels(undistortion_->pinhole());
    } else {
      camera_ = InLibraryPixels(camera);
    }
    detector_.setZAlignedWithCameraAxis(true);
    cv::Mat tag;
    cv::aruco::drawMarker(cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11), 0,
                          kBlackModules * kTexelsPerModule, tag, 1);
    const int border =
        static_cast<int>(std::lround((kPictureModules - kBlackModules) / 2.0 * kTexelsPerModule));
    cv::copyMakeBorder(tag, tag, border, border, border, border, cv::BORDER_CONSTANT,
                       cv::Scalar(255));
    auto picture = std::make_shared<vpImage<unsigned char>>(static_cast<unsigned>(tag.rows),
                                                            static_cast<unsigned>(tag.cols));
    for (int row = 0; row < tag.rows; ++row) {
      std::memcpy((*picture)[row], tag.ptr<unsigned char>(row), static_cast<std::size_t>(tag.cols));
    }
    print_.picture.image = picture;
    print_.picture.width_m = tag_size_m_ * tag.cols / (kBlackModules * kTexelsPerModule);
    const double h = 0.5 * tag_size_m_;
    print_.outline_m = {{{-h, -h}, {h, -h}, {h, h}, {-h, h}}};
    print_.description = "AprilTag 36h11 id 0, black square " + Fixed(tag_size_m_, 3) + " m";
  }

  std::string Name() const override { return "apriltag-36h11"; }
  const MarkerPrint& Print() const override { return print_; }

  MarkerPose Find(const vpImage<unsigned char>& image) override {
    MarkerPose result;
    auto start = std::chrono::steady_clock::now();
    detector_.detect(undistortion_ ? undistortion_->Undistort(image) : image);
    // The largest tag 36h11 id 0.
    const std::vector<int> ids = detector_.getTagsId();
    int best = -1;
    double best_area = 0.0;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] != 0) continue;
      const double area = PolygonArea(detector_.getPolygon(i));
      if (best < 0 || area > best_area) {
        best = static_cast<int>(i);
        best_area = area;
      }
    }
    result.detect_us = MicrosecondsSince(start);
    if (best < 0) {
      result.status = MarkerStatus::kNotFound;
      result.message =
          ids.empty() ? "no tag 36h11" : std::to_string(ids.size()) + " tag(s) 36h11, none of id 0";
      return result;
    }
    start = std::chrono::steady_clock::now();
    vpHomogeneousMatrix cMt;
    const bool posed = detector_.getPose(static_cast<std::size_t>(best), tag_size_m_, camera_, cMt);
    result.pose_us = MicrosecondsSince(start);
    if (!posed) {
      result.status = MarkerStatus::kNoPose;
      result.message = "vpDetectorAprilTag::getPose failed";
      return result;
    }
    result.status = MarkerStatus::kOk;
    result.cMo = cMt * SheetFromTag();
    return result;
  }

 private:
  std::unique_ptr<LensUndistortion> undistortion_;  // null for a camera without a lens
  vpCameraParameters camera_;  // of the frames the detector sees, in the library's pixels
  double tag_size_m_;
  vpDetectorAprilTag detector_;
  MarkerPrint print_;
};

}  // namespace

double AprilTagBlackSide(const LineTarget& sheet) {
  return std::min(sheet.board_width_m, sheet.board_height_m) * kBlackModules / kPictureModules;
}

std::unique_ptr<MarkerMethod> MakeAprilTagMethod(const LineTarget& sheet, const Lens& camera,
                                                 int width, int height) {
  return std::make_unique<AprilTagMethod>(sheet, camera, width, height);
}

}  // namespace oal
