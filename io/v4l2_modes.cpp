#include "io/v4l2_modes.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "base/format.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

std::string FourccOf(std::uint32_t code) {
  std::string text;
  for (int shift = 0; shift < 32; shift += 8) {
    const char c = static_cast<char>((code >> shift) & 0xff);
    if (c != ' ' && c != '\0') text += c;
  }
  return text;
}

// ioctl, again while a signal interrupts it.
int Ioctl(int fd, unsigned long request, void* argument) {
  int result;
  do {
    result = ::ioctl(fd, request, argument);
  } while (result == -1 && errno == EINTR);
  return result;
}

// An open device, closed on leaving.
class Device {
 public:
  explicit Device(const std::string& path) : fd_(::open(path.c_str(), O_RDWR | O_NONBLOCK)) {}
  ~Device() {
    if (fd_ >= 0) ::close(fd_);
  }
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  int fd() const { return fd_; }

 private:
  int fd_;
};

std::vector<double> RatesOf(int fd, std::uint32_t format, int width, int height) {
  std::vector<double> rates;
  v4l2_frmivalenum interval{};
  interval.pixel_format = format;
  interval.width = static_cast<std::uint32_t>(width);
  interval.height = static_cast<std::uint32_t>(height);
  for (interval.index = 0; Ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &interval) == 0;
       ++interval.index) {
    if (interval.type == V4L2_FRMIVAL_TYPE_DISCRETE && interval.discrete.numerator > 0) {
      rates.push_back(static_cast<double>(interval.discrete.denominator) /
                      interval.discrete.numerator);
    } else if (interval.stepwise.min.numerator > 0) {
      rates.push_back(static_cast<double>(interval.stepwise.min.denominator) /
                      interval.stepwise.min.numerator);
      break;
    }
  }
  std::sort(rates.rbegin(), rates.rend());
  return rates;
}

std::vector<CameraMode> ModesOf(int fd) {
  std::vector<CameraMode> modes;
  v4l2_fmtdesc format{};
  format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  for (format.index = 0; Ioctl(fd, VIDIOC_ENUM_FMT, &format) == 0; ++format.index) {
    v4l2_frmsizeenum size{};
    size.pixel_format = format.pixelformat;
    for (size.index = 0; Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &size) == 0; ++size.index) {
      const bool discrete = size.type == V4L2_FRMSIZE_TYPE_DISCRETE;
      const int width = static_cast<int>(discrete ? size.discrete.width : size.stepwise.max_width);
      const int height =
          static_cast<int>(discrete ? size.discrete.height : size.stepwise.max_height);
      modes.push_back({FourccOf(format.pixelformat), width, height,
                       RatesOf(fd, format.pixelformat, width, height)});
      if (!discrete) break;
    }
  }
  return modes;
}

bool SameFormat(const CameraMode& mode, CameraFormat format) {
  switch (format) {
    case CameraFormat::kMjpeg:
      return mode.fourcc == "MJPG" || mode.fourcc == "JPEG";
    case CameraFormat::kYuyv:
      return mode.fourcc == "YUYV";
    case CameraFormat::kGrey:
      return mode.fourcc == "GREY";
    case CameraFormat::kAuto:
      return mode.fourcc == "MJPG" || mode.fourcc == "JPEG" || mode.fourcc == "YUYV" ||
             mode.fourcc == "GREY";
  }
  return false;
}

bool GivesRate(const CameraMode& mode, double fps) {
  if (fps <= 0.0 || mode.fps.empty()) return true;
  return std::any_of(mode.fps.begin(), mode.fps.end(),
                     [&](double rate) { return std::fabs(rate - fps) < 0.01 * fps + 0.05; });
}

// Preference among formats under kAuto: uncompressed first, then MJPEG, then grey.
int Preference(const CameraMode& mode) {
  if (mode.fourcc == "YUYV") return 0;
  if (mode.fourcc == "MJPG" || mode.fourcc == "JPEG") return 1;
  return 2;
}

std::string Asked(const CameraRequest& request) {
  std::string text = ToString(request.format);
  if (request.width > 0)
    text += " " + std::to_string(request.width) + "x" + std::to_string(request.height);
  if (request.fps > 0.0) text += " at " + Number(request.fps) + " fps";
  return text;
}

}  // namespace

std::string ToString(CameraFormat format) {
  switch (format) {
    case CameraFormat::kAuto:
      return "auto";
    case CameraFormat::kMjpeg:
      return "mjpeg";
    case CameraFormat::kYuyv:
      return "yuyv";
    case CameraFormat::kGrey:
      return "grey";
  }
  return "auto";
}

std::optional<CameraFormat> CameraFormatFromString(const std::string& name) {
  const std::string lower = Lowercase(name);
  for (const CameraFormat format :
       {CameraFormat::kAuto, CameraFormat::kMjpeg, CameraFormat::kYuyv, CameraFormat::kGrey}) {
    if (lower == ToString(format)) return format;
  }
  return std::nullopt;
}

std::string CameraMode::Describe() const {
  std::string text = fourcc + " " + std::to_string(width) + "x" + std::to_string(height);
  if (fps.empty()) return text;
  text += " at ";
  for (std::size_t i = 0; i < fps.size(); ++i) text += (i == 0 ? "" : ", ") + Number(fps[i], 4);
  return text + " fps";
}

std::vector<CameraDevice> ListCameras(const std::string& dev_dir) {
  std::vector<std::string> paths;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dev_dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("video", 0) == 0) paths.push_back(entry.path().string());
  }
  std::sort(paths.begin(), paths.end(), [](const std::string& a, const std::string& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;  // video2 before video10
  });
  std::vector<CameraDevice> cameras;
  for (const std::string& path : paths) {
    const Device device(path);
    if (device.fd() < 0) continue;
    v4l2_capability capability{};
    if (Ioctl(device.fd(), VIDIOC_QUERYCAP, &capability) != 0) continue;
    const std::uint32_t caps = (capability.capabilities & V4L2_CAP_DEVICE_CAPS) != 0
                                   ? capability.device_caps
                                   : capability.capabilities;
    if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) continue;  // a UVC metadata node
    CameraDevice camera;
    camera.path = path;
    camera.card = reinterpret_cast<const char*>(capability.card);
    camera.bus = reinterpret_cast<const char*>(capability.bus_info);
    camera.modes = ModesOf(device.fd());
    cameras.push_back(std::move(camera));
  }
  return cameras;
}

std::vector<CameraMode> ModesOfDevice(const std::string& path) {
  const Device device(path);
  return device.fd() < 0 ? std::vector<CameraMode>() : ModesOf(device.fd());
}

void CameraRequest::Check() const {
  if (width < 0 || height < 0 || (width > 0) != (height > 0)) {
    throw std::invalid_argument("CameraRequest::width, height = " + std::to_string(width) + "x" +
                                std::to_string(height) + ": both above 0, or both 0 (the largest)");
  }
  if (!(fps >= 0.0) || fps > 1000.0) {
    throw std::invalid_argument("CameraRequest::fps = " + Number(fps) +
                                ": 0 (the highest) or a rate up to 1000");
  }
}

ChosenMode ChooseCameraMode(const std::vector<CameraMode>& modes, const CameraRequest& request) {
  request.Check();
  const CameraMode* best = nullptr;
  for (const CameraMode& mode : modes) {
    if (!SameFormat(mode, request.format)) continue;
    if (request.width > 0 && (mode.width != request.width || mode.height != request.height)) {
      continue;
    }
    if (!GivesRate(mode, request.fps)) continue;
    if (best == nullptr) {
      best = &mode;
      continue;
    }
    const long area = static_cast<long>(mode.width) * mode.height;
    const long best_area = static_cast<long>(best->width) * best->height;
    if (request.width == 0 && area != best_area) {
      if (area > best_area) best = &mode;
      continue;
    }
    // The same size: the highest rate unless one was asked, then the preferred format.
    const double rate = mode.fps.empty() ? 0.0 : mode.fps.front();
    const double best_rate = best->fps.empty() ? 0.0 : best->fps.front();
    if (request.fps == 0.0 && rate != best_rate) {
      if (rate > best_rate) best = &mode;
      continue;
    }
    if (Preference(mode) < Preference(*best)) best = &mode;
  }
  if (best != nullptr) {
    const double fps =
        request.fps > 0.0 ? request.fps : (best->fps.empty() ? 0.0 : best->fps.front());
    return {*best, fps};
  }
  std::ostringstream message;
  message << "the camera gives no " << Asked(request) << " mode";
  std::string nearest;
  for (const CameraMode& mode : modes) {
    const bool same_size =
        request.width > 0 && mode.width == request.width && mode.height == request.height;
    if (same_size || SameFormat(mode, request.format)) nearest += "\n  " + mode.Describe();
  }
  message << (nearest.empty() ? std::string("; it lists no mode of that size or format")
                              : "; nearest it gives:" + nearest);
  throw std::runtime_error(message.str());
}

CameraRequest ParseCameraRequest(const std::string& text) {
  CameraRequest request;
  std::string rest = text;
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument("'" + text + "': " + why +
                                " (e.g. mjpeg:1280x720@30, yuyv:640x480, 1920x1080@30, auto)");
  };
  const std::size_t colon = rest.find(':');
  const std::string head = rest.substr(0, colon);
  if (const auto format = CameraFormatFromString(head)) {
    request.format = *format;
    rest = colon == std::string::npos ? "" : rest.substr(colon + 1);
  } else if (colon != std::string::npos) {
    fail("'" + head + "' is not a format: auto, mjpeg, yuyv or grey");
  }
  if (rest.empty()) return request;
  const std::size_t at = rest.find('@');
  const std::string size = rest.substr(0, at);
  // A whole number or decimal, nothing after it; nullopt otherwise.
  const auto number = [](const std::string& digits) -> std::optional<double> {
    if (digits.empty() || !(std::isdigit(static_cast<unsigned char>(digits[0])) != 0)) {
      return std::nullopt;
    }
    char* end = nullptr;
    const double value = std::strtod(digits.c_str(), &end);
    return *end == '\0' ? std::optional<double>(value) : std::nullopt;
  };
  if (!size.empty()) {
    const std::size_t x = size.find('x');
    const auto width = number(size.substr(0, x)), height = number(size.substr(x + 1));
    if (x == std::string::npos || !width || !height || *width != std::floor(*width) ||
        *height != std::floor(*height) || *width < 1 || *height < 1 || *width > 100000 ||
        *height > 100000) {
      fail("the size is WIDTHxHEIGHT, whole pixels above 0");
    }
    request.width = static_cast<int>(*width);
    request.height = static_cast<int>(*height);
  }
  if (at != std::string::npos) {
    const auto fps = number(rest.substr(at + 1));
    if (!fps || !(*fps > 0.0) || *fps > 1000.0)
      fail("the rate after @ is above 0 and at most 1000");
    request.fps = *fps;
  }
  return request;
}

}  // namespace oal
