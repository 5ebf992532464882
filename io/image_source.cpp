#include "io/image_source.h"

#include <sys/time.h>
#include <visp3/core/vpConfig.h>
#include <visp3/core/vpException.h>
#include <visp3/core/vpImage.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <stdexcept>

#include "base/format.h"
#ifdef VISP_HAVE_V4L2
#include <visp3/sensor/vpV4l2Grabber.h>
#endif

namespace oal {
namespace {

namespace fs = std::filesystem;

std::string Quoted(const fs::path& path) {
  return "'" + path.string() + "'";
}

std::string LowerExtension(const std::string& path) {
  return Lowercase(fs::path(path).extension().string());
}

bool OneOf(const std::string& value, std::initializer_list<const char*> choices) {
  return std::any_of(choices.begin(), choices.end(),
                     [&value](const char* choice) { return value == choice; });
}

bool StartsWith(const std::vector<unsigned char>& bytes,
                std::initializer_list<unsigned char> prefix) {
  return bytes.size() >= prefix.size() && std::equal(prefix.begin(), prefix.end(), bytes.begin());
}

std::uint32_t BigEndian(const std::vector<unsigned char>& bytes, std::size_t at, int size) {
  std::uint32_t value = 0;
  for (int k = 0; k < size; ++k) value = (value << 8) | bytes[at + static_cast<std::size_t>(k)];
  return value;
}

// Why a JPEG stream is cut short, or "": the header segments up to the first scan must be
// whole, and an end-of-image marker (0xFFD9) must follow the scan. Entropy-coded data never
// holds 0xFF 0xD9 (a data 0xFF is followed by 0x00), so that marker anywhere after the first
// scan's header is the image's end, whatever trails it (zero padding, camera trailers).
// libjpeg itself only warns ("Premature end of JPEG file") and returns grey rows.
std::string JpegTruncation(const std::vector<unsigned char>& bytes) {
  std::size_t at = 2;  // after SOI
  while (at + 1 < bytes.size()) {
    if (bytes[at] != 0xFF) return "";  // not a marker: let the decoder judge
    const unsigned char marker = bytes[at + 1];
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0xD9) return "";                               // EOI before any scan
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length
      at += 2;
      continue;
    }
    if (at + 3 >= bytes.size()) break;
    const std::size_t end = at + 2 + BigEndian(bytes, at + 2, 2);
    if (end > bytes.size()) break;
    if (marker == 0xDA) {  // start of scan: the rest is data up to EOI
      for (std::size_t k = end; k + 1 < bytes.size(); ++k) {
        if (bytes[k] == 0xFF && bytes[k + 1] == 0xD9) return "";
      }
      return "truncated JPEG (no end-of-image marker after the image data)";
    }
    at = end;
  }
  return "truncated JPEG (the file ends inside its header)";
}

// Why a PNG stream is cut short, or "": its chunks must be whole up to IEND.
std::string PngTruncation(const std::vector<unsigned char>& bytes) {
  std::size_t at = 8;  // after the signature
  while (at + 8 <= bytes.size()) {
    const std::uint64_t length = BigEndian(bytes, at, 4);
    if (length > 0x7FFFFFFFu) return "";  // corrupt, not short: let the decoder judge
    const bool iend = BigEndian(bytes, at + 4, 4) == 0x49454E44u;  // "IEND"
    at += 12 + static_cast<std::size_t>(length);                   // length, type, data, CRC
    if (at > bytes.size()) break;
    if (iend) return "";
  }
  return "truncated PNG (the file ends before its IEND chunk)";
}

// Why the image file `bytes` is cut short, or "" (also for formats not checked here: their
// decoders fail on a short file by themselves).
std::string Truncation(const std::vector<unsigned char>& bytes) {
  if (StartsWith(bytes, {0xFF, 0xD8, 0xFF})) return JpegTruncation(bytes);
  if (StartsWith(bytes, {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'})) return PngTruncation(bytes);
  return "";
}

std::vector<unsigned char> ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = in ? static_cast<std::streamoff>(in.tellg()) : -1;
  std::vector<unsigned char> bytes(size > 0 ? static_cast<std::size_t>(size) : 0);
  if (size < 0 || !in.seekg(0) ||
      !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()))) {
    throw std::runtime_error("cannot read " + Quoted(path));
  }
  return bytes;
}

cv::Mat DecodeGray(const fs::path& path) {
  if (!fs::exists(path)) throw std::runtime_error("no such file " + Quoted(path));
  return DecodeGrayImage(ReadBytes(path), path.string());
}

// A list of image files, decoded one at a time.
class ImageListSource : public ImageSource {
 public:
  ImageListSource(std::string name, std::vector<fs::path> paths, cv::Mat first = cv::Mat())
      : name_(std::move(name)), paths_(std::move(paths)), first_(std::move(first)) {}

  bool Next(Frame* frame) override {
    if (next_ >= paths_.size()) return false;
    const fs::path& path = paths_[next_++];  // past it even if it does not decode
    frame->source = path.string();           // also when it does not decode
    frame->taken_s.reset();
    frame->gray = (next_ == 1 && !first_.empty()) ? first_ : DecodeGray(path);
    return true;
  }
  std::string Name() const override { return name_; }
  int ExpectedFrames() const override { return static_cast<int>(paths_.size()); }

 private:
  std::string name_;
  std::vector<fs::path> paths_;
  cv::Mat first_;  ///< decoded at open time to report a bad single image early
  std::size_t next_ = 0;
};

std::unique_ptr<ImageSource> OpenImageFile(const std::string& spec) {
  // Decoded now, so a bad image fails before any output is started.
  cv::Mat first = DecodeGray(spec);
  return std::make_unique<ImageListSource>("image " + Quoted(spec), std::vector<fs::path>{spec},
                                           std::move(first));
}

std::string SkippedWarning(const fs::path& directory, const std::vector<std::string>& skipped) {
  constexpr std::size_t kListed = 3;
  std::string names;
  for (std::size_t i = 0; i < skipped.size() && i < kListed; ++i) {
    names += (i == 0 ? "" : ", ") + skipped[i];
  }
  if (skipped.size() > kListed) names += ", ...";
  return "skipped " + std::to_string(skipped.size()) + " non-image entr" +
         (skipped.size() == 1 ? "y" : "ies") + " in " + Quoted(directory) + ": " + names;
}

std::unique_ptr<ImageSource> OpenDirectory(const fs::path& directory,
                                           std::vector<std::string>* warnings) {
  std::vector<fs::path> images;
  std::vector<std::string> skipped;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory)) {
    if (entry.is_regular_file() && HasImageExtension(entry.path().string())) {
      images.push_back(entry.path());
    } else if (!(entry.is_regular_file() && IsCompanionFile(entry.path().string()))) {
      skipped.push_back(entry.path().filename().string());
    }
  }
  if (images.empty()) throw std::runtime_error("directory " + Quoted(directory) + " has no images");
  std::sort(images.begin(), images.end(), [](const fs::path& a, const fs::path& b) {
    return a.filename().string() < b.filename().string();
  });
  std::sort(skipped.begin(), skipped.end());
  if (!skipped.empty() && warnings != nullptr)
    warnings->push_back(SkippedWarning(directory, skipped));
  return std::make_unique<ImageListSource>("directory " + Quoted(directory), std::move(images));
}

// After the file `missing` that ends a pattern's sequence at `index`: if any of the next
// kGapLookahead indices exists, a warning naming the gap and the files found after it.
constexpr int kGapLookahead = 100;

std::optional<std::string> GapWarning(const std::string& pattern, int index) {
  int after = 0, first = -1, last = -1;
  for (int k = index + 1; k <= (last < 0 ? index : last) + kGapLookahead; ++k) {
    if (!fs::exists(ExpandPattern(pattern, k))) continue;
    ++after;
    if (first < 0) first = k;
    last = k;
  }
  if (after == 0) return std::nullopt;
  const bool one = after == 1;
  return "pattern '" + pattern + "': the sequence ends at the missing file " +
         Quoted(ExpandPattern(pattern, index)) + "; " + std::to_string(after) +
         (one ? " file" : " files") + " after the gap (" + Quoted(ExpandPattern(pattern, first)) +
         (one ? "" : " ... " + Quoted(ExpandPattern(pattern, last))) + (one ? ") is" : ") are") +
         " not read";
}

std::unique_ptr<ImageSource> OpenPattern(const std::string& pattern,
                                         std::vector<std::string>* warnings) {
  int index = 0;
  if (!fs::exists(ExpandPattern(pattern, 0))) index = 1;
  if (!fs::exists(ExpandPattern(pattern, index))) {
    throw std::runtime_error("no file matches the pattern '" + pattern + "' (tried '" +
                             ExpandPattern(pattern, 0) + "' and '" + ExpandPattern(pattern, 1) +
                             "')");
  }
  std::vector<fs::path> paths;
  for (; fs::exists(ExpandPattern(pattern, index)); ++index) {
    paths.emplace_back(ExpandPattern(pattern, index));
  }
  if (warnings != nullptr) {
    if (auto gap = GapWarning(pattern, index)) warnings->push_back(*gap);
  }
  return std::make_unique<ImageListSource>("pattern '" + pattern + "'", std::move(paths));
}

cv::Mat ToGray(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat gray;
  cv::cvtColor(image, gray, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return gray;
}

class VideoSource : public ImageSource {
 public:
  explicit VideoSource(const std::string& path) : path_(path) {
    // FFmpeg reads the video containers; naming it spares a file the probe of OpenCV's camera
    // backends (gPhoto2 scans the USB bus and keeps what it found, GStreamer prints errors).
    if (!capture_.open(path, cv::CAP_FFMPEG) || !capture_.isOpened()) {
      throw std::runtime_error("cannot open video " + Quoted(path) +
                               " (not a video, or no decoder for it)");
    }
    // The first frame is read now, so an empty video fails before any output is started.
    if (!capture_.read(buffer_) || buffer_.empty()) {
      throw std::runtime_error("video " + Quoted(path) + " has no frames");
    }
    pending_ = true;
  }

  bool Next(Frame* frame) override {
    if (!pending_ && (!capture_.read(buffer_) || buffer_.empty())) return false;
    pending_ = false;
    frame->gray = ToGray(buffer_);
    frame->source = path_ + "#" + std::to_string(index_++);
    frame->taken_s.reset();
    return true;
  }
  std::string Name() const override { return "video " + Quoted(path_); }
  int ExpectedFrames() const override {
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    return count >= 1.0 && count < 1e9 ? static_cast<int>(count) : -1;
  }

 private:
  std::string path_;
  cv::VideoCapture capture_;
  cv::Mat buffer_;
  bool pending_ = false;
  int index_ = 0;
};

#ifdef VISP_HAVE_V4L2
class V4l2Source : public ImageSource {
 public:
  V4l2Source(const std::string& device, int width, int height, double fps) : device_(device) {
    grabber_.setDevice(device);
    grabber_.setInput(0);  // USB cameras have one input; ViSP's default (2) is for TV boards
    grabber_.setScale(1);  // full resolution; ViSP's default halves it
    if (width > 0) grabber_.setWidth(static_cast<unsigned>(width));
    if (height > 0) grabber_.setHeight(static_cast<unsigned>(height));
    if (fps == 25.0) grabber_.setFramerate(vpV4l2Grabber::framerate_25fps);
    if (fps == 50.0) grabber_.setFramerate(vpV4l2Grabber::framerate_50fps);
    try {
      grabber_.open(image_);
    } catch (const vpException& error) {
      throw std::runtime_error("cannot open V4L2 device '" + device +
                               "': " + error.getStringMessage());
    }
  }

  bool Next(Frame* frame) override {
    frame->source = device_ + "#" + std::to_string(index_++);
    try {
      timeval taken{};
      grabber_.acquire(image_, taken);
      // The driver's buffer timestamp (UVC cameras: the monotonic clock, when the frame's
      // first byte arrived); 0 when it gives none.
      frame->taken_s.reset();
      if (taken.tv_sec != 0 || taken.tv_usec != 0) {
        frame->taken_s =
            static_cast<double>(taken.tv_sec) + 1e-6 * static_cast<double>(taken.tv_usec);
      }
    } catch (const vpException& error) {
      throw std::runtime_error("cannot grab from V4L2 device '" + device_ +
                               "': " + error.getStringMessage());
    }
    // A header over ViSP's buffer: no copy, valid until the next acquire.
    frame->gray = cv::Mat(static_cast<int>(image_.getHeight()), static_cast<int>(image_.getWidth()),
                          CV_8UC1, image_.bitmap);
    return true;
  }
  std::string Name() const override { return "V4L2 device '" + device_ + "'"; }

 private:
  std::string device_;
  vpV4l2Grabber grabber_;
  vpImage<unsigned char> image_;
  int index_ = 0;
};
#endif

// A V4L2 camera through OpenCV's V4L2 backend, in the mode asked: MJPEG decoded there (the
// only way most webcams give 720p and 1080p at 30 frames a second), or a rate vpV4l2Grabber
// cannot ask for.
class OpenCvCameraSource : public ImageSource {
 public:
  OpenCvCameraSource(const std::string& device, const ChosenMode& chosen) : device_(device) {
    if (!capture_.open(device, cv::CAP_V4L2)) {
      throw std::runtime_error("cannot open V4L2 device '" + device + "' through OpenCV");
    }
    const std::string& fourcc = chosen.mode.fourcc;
    capture_.set(cv::CAP_PROP_FOURCC,
                 cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]));
    capture_.set(cv::CAP_PROP_FRAME_WIDTH, chosen.mode.width);
    capture_.set(cv::CAP_PROP_FRAME_HEIGHT, chosen.mode.height);
    if (chosen.fps > 0.0) capture_.set(cv::CAP_PROP_FPS, chosen.fps);
    const int width = static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_WIDTH));
    const int height = static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_HEIGHT));
    if (width != chosen.mode.width || height != chosen.mode.height) {
      throw std::runtime_error("V4L2 device '" + device + "' was asked for " +
                               chosen.mode.Describe() + " and gives " + std::to_string(width) +
                               "x" + std::to_string(height));
    }
  }

  bool Next(Frame* frame) override {
    frame->source = device_ + "#" + std::to_string(index_++);
    if (!capture_.read(buffer_) || buffer_.empty()) {
      throw std::runtime_error("cannot grab from V4L2 device '" + device_ + "'");
    }
    // The driver's buffer timestamp, ms (UVC cameras: the monotonic clock); 0 when none.
    const double taken_ms = capture_.get(cv::CAP_PROP_POS_MSEC);
    frame->taken_s.reset();
    if (taken_ms > 0.0) frame->taken_s = 1e-3 * taken_ms;
    if (buffer_.channels() == 1) {
      frame->gray = buffer_;
    } else {
      cv::cvtColor(buffer_, gray_, cv::COLOR_BGR2GRAY);
      frame->gray = gray_;
    }
    return true;
  }
  std::string Name() const override { return "V4L2 device '" + device_ + "'"; }

 private:
  std::string device_;
  cv::VideoCapture capture_;
  cv::Mat buffer_, gray_;
  int index_ = 0;
};

// Parsed "prefix%0<width>dsuffix"; "%%" stands for a literal '%'.
struct Pattern {
  std::string prefix, suffix;
  int width = 0;
  bool zero_pad = false;
};

Pattern ParsePattern(const std::string& text) {
  Pattern pattern;
  bool found = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    std::string& out = found ? pattern.suffix : pattern.prefix;
    if (text[i] != '%') {
      out += text[i];
      continue;
    }
    if (i + 1 < text.size() && text[i + 1] == '%') {
      out += '%';
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    const bool zero = j < text.size() && text[j] == '0';
    if (zero) ++j;
    int width = 0;
    for (; j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])) && width < 100;
         ++j) {
      width = width * 10 + (text[j] - '0');
    }
    if (found || j >= text.size() || text[j] != 'd') {
      throw std::runtime_error("pattern '" + text +
                               "' must have exactly one %d conversion, e.g. img%04d.png");
    }
    pattern.zero_pad = zero;
    pattern.width = width;
    found = true;
    i = j;
  }
  if (!found) throw std::runtime_error("pattern '" + text + "' has no %d conversion");
  return pattern;
}

}  // namespace

cv::Mat DecodeGrayImage(const std::vector<unsigned char>& bytes, const std::string& name) {
  if (const std::string truncation = Truncation(bytes); !truncation.empty()) {
    throw std::runtime_error("cannot decode image " + Quoted(name) + ": " + truncation);
  }
  cv::Mat gray = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  if (gray.empty()) {
    throw std::runtime_error("cannot decode image " + Quoted(name) +
                             " (not an image, truncated, or a format OpenCV cannot read)");
  }
  return gray;
}

cv::Mat ReadGrayImageFile(const std::string& path) {
  return DecodeGray(path);
}

std::shared_ptr<const vpImage<unsigned char>> ReadGrayImage(const std::string& path) {
  const cv::Mat gray = DecodeGray(path);
  auto image = std::make_shared<vpImage<unsigned char>>(static_cast<unsigned>(gray.rows),
                                                        static_cast<unsigned>(gray.cols));
  for (int r = 0; r < gray.rows; ++r) {
    std::copy_n(gray.ptr<unsigned char>(r), gray.cols, (*image)[r]);
  }
  return image;
}

bool HasImageExtension(const std::string& path) {
  return OneOf(LowerExtension(path),
               {".png", ".pgm", ".ppm",  ".pnm",  ".pbm", ".pam", ".jpg", ".jpeg", ".jpe", ".bmp",
                ".dib", ".tif", ".tiff", ".webp", ".jp2", ".sr",  ".ras", ".exr",  ".hdr", ".pic"});
}

bool IsCompanionFile(const std::string& path) {
  const fs::path file(path);
  const std::string name = file.filename().string();
  const auto ends_with = [&name](const std::string& end) {
    return name.size() >= end.size() &&
           name.compare(name.size() - end.size(), end.size(), end) == 0;
  };
  return name == "camera.xml" || name == "camera.yaml" || name == "target.yaml" ||
         LowerExtension(path) == ".json" || ends_with(".truth.csv");
}

bool HasVideoExtension(const std::string& path) {
  return OneOf(LowerExtension(path),
               {".avi", ".mp4", ".mkv", ".mov", ".webm", ".mpg", ".mpeg", ".m4v", ".wmv", ".flv",
                ".ogv", ".3gp", ".mjpg", ".mjpeg", ".h264", ".ts"});
}

std::string ExpandPattern(const std::string& text, int index) {
  const Pattern pattern = ParsePattern(text);
  std::string number = std::to_string(index);
  if (static_cast<int>(number.size()) < pattern.width) {
    number.insert(0, static_cast<std::size_t>(pattern.width) - number.size(),
                  pattern.zero_pad ? '0' : ' ');
  }
  return pattern.prefix + number + pattern.suffix;
}

std::unique_ptr<ImageSource> OpenV4l2Source(const std::string& device,
                                            const V4l2Settings& settings) {
  settings.Check();
  if (!fs::exists(device)) throw std::runtime_error("no V4L2 device at " + device);
  const std::vector<CameraMode> modes = ModesOfDevice(device);
  if (!modes.empty()) {
    const ChosenMode chosen = ChooseCameraMode(modes, settings);
    const bool grabber_can = chosen.mode.fourcc != "MJPG" && chosen.mode.fourcc != "JPEG" &&
                             (chosen.fps == 0.0 || chosen.fps == 25.0 || chosen.fps == 50.0);
#ifdef VISP_HAVE_V4L2
    if (grabber_can) {
      return std::make_unique<V4l2Source>(device, chosen.mode.width, chosen.mode.height,
                                          chosen.fps);
    }
#endif
    return std::make_unique<OpenCvCameraSource>(device, chosen);
  }
#ifdef VISP_HAVE_V4L2
  return std::make_unique<V4l2Source>(device, settings.width, settings.height, settings.fps);
#else
  throw std::runtime_error("cannot read " + device + ": this ViSP build has no V4L2 support");
#endif
}

bool IsDevicePath(const std::string& spec) {
  return spec.rfind("/dev/video", 0) == 0 || spec.rfind("/dev/v4l/", 0) == 0;
}

std::unique_ptr<ImageSource> OpenImageSource(const std::string& spec,
                                             std::vector<std::string>* warnings) {
  if (spec.empty()) throw std::runtime_error("empty input name");
  if (IsDevicePath(spec)) return OpenV4l2Source(spec);
  if (spec.find('%') != std::string::npos && !fs::exists(spec)) return OpenPattern(spec, warnings);
  if (!fs::exists(spec)) throw std::runtime_error("no such file or directory '" + spec + "'");
  if (fs::is_directory(spec)) return OpenDirectory(spec, warnings);
  if (HasVideoExtension(spec)) return std::make_unique<VideoSource>(spec);
  if (HasImageExtension(spec) || cv::haveImageReader(spec)) return OpenImageFile(spec);
  throw std::runtime_error("unsupported input '" + spec +
                           "' (expected an image, a directory of images, a printf pattern such "
                           "as img%04d.png, a video or /dev/videoN)");
}

}  // namespace oal
