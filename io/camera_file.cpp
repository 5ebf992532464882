#include "io/camera_file.h"

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <visp3/core/vpException.h>
#include <visp3/core/vpXmlParserCamera.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "base/format.h"
#include "detector/lens.h"
#include "io/atomic_file.h"
#include "io/camera_yaml.h"

namespace oal {
namespace {

constexpr const char* kWithDistortion = "perspectiveProjWithDistortion";
constexpr const char* kWithoutDistortion = "perspectiveProjWithoutDistortion";

// vpXmlParserCamera prints to std::cout ("Found camera with name ...") and std::cerr; the
// detect command writes JSON lines to stdout, so both are muted while it runs.
class MuteStandardStreams {
 public:
  MuteStandardStreams()
      : out_(std::cout.rdbuf(sink_.rdbuf())), err_(std::cerr.rdbuf(sink_.rdbuf())) {}
  ~MuteStandardStreams() {
    std::cout.rdbuf(out_);
    std::cerr.rdbuf(err_);
  }
  MuteStandardStreams(const MuteStandardStreams&) = delete;
  MuteStandardStreams& operator=(const MuteStandardStreams&) = delete;

 private:
  std::ostringstream sink_;
  std::streambuf* out_;
  std::streambuf* err_;
};

// One numeric parameter of a <model> (<px>, <u0>, <kdu>...), where it is in the file.
struct ModelField {
  std::string name;
  std::string text;
  long line = 0;
};

// What the file says about one <camera>, enough to ask vpXmlParserCamera for it and to check
// its parameters first (ViSP reads "abc" as 0 and then fails with "Camera parameter px = 0",
// naming neither the file nor the field).
struct CameraEntry {
  std::string name;
  unsigned int width = 0, height = 0;
  bool with_distortion = false, without_distortion = false;
  std::vector<ModelField> with_fields, without_fields;  ///< of the first model of each type
};

struct XmlDocFree {
  void operator()(xmlDoc* doc) const { xmlFreeDoc(doc); }
};

struct XmlStringFree {
  void operator()(xmlChar* text) const { xmlFree(text); }
};

std::string ChildText(const xmlNode* node) {
  const std::unique_ptr<xmlChar, XmlStringFree> text(xmlNodeGetContent(node));
  return text ? std::string(reinterpret_cast<const char*>(text.get())) : std::string();
}

bool Named(const xmlNode* node, const char* name) {
  return node->type == XML_ELEMENT_NODE &&
         xmlStrcmp(node->name, reinterpret_cast<const xmlChar*>(name)) == 0;
}

unsigned int ToUnsigned(const std::string& text) {
  try {
    return static_cast<unsigned int>(std::stoul(text));
  } catch (const std::exception&) {
    return 0;
  }
}

// Trims the whitespace pugixml would also ignore around element text.
std::string Trimmed(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(" \t\r\n") - begin + 1);
}

CameraEntry ReadEntry(const xmlNode* camera) {
  CameraEntry entry;
  for (const xmlNode* child = camera->children; child != nullptr; child = child->next) {
    if (Named(child, "name")) entry.name = Trimmed(ChildText(child));
    if (Named(child, "image_width")) entry.width = ToUnsigned(ChildText(child));
    if (Named(child, "image_height")) entry.height = ToUnsigned(ChildText(child));
    if (!Named(child, "model")) continue;
    std::string type;
    std::vector<ModelField> fields;
    for (const xmlNode* field = child->children; field != nullptr; field = field->next) {
      if (Named(field, "type")) type = Trimmed(ChildText(field));
      for (const char* parameter : {"px", "py", "u0", "v0", "kud", "kdu"}) {
        if (Named(field, parameter)) {
          fields.push_back({parameter, Trimmed(ChildText(field)), xmlGetLineNo(field)});
        }
      }
    }
    if (type == kWithDistortion && !entry.with_distortion) entry.with_fields = fields;
    if (type == kWithoutDistortion && !entry.without_distortion) entry.without_fields = fields;
    entry.with_distortion |= type == kWithDistortion;
    entry.without_distortion |= type == kWithoutDistortion;
  }
  return entry;
}

// Each parameter of the model a finite number, px and py > 0; else an error naming the file,
// the line, the camera, the model and the field.
void CheckModelFields(const std::vector<ModelField>& fields, const std::string& path,
                      const std::string& camera_name, const char* model) {
  for (const ModelField& field : fields) {
    const std::string where = path + ":" + std::to_string(field.line) + ": camera '" + camera_name +
                              "', model " + model + ": <" + field.name + ">";
    char* end = nullptr;
    const double value = std::strtod(field.text.c_str(), &end);
    if (field.text.empty() || end != field.text.c_str() + field.text.size() ||
        !std::isfinite(value)) {
      throw std::runtime_error(where + " is '" + field.text + "', not a number");
    }
    if ((field.name == "px" || field.name == "py") && !(value > 0.0)) {
      throw std::runtime_error(where + " = " + field.text +
                               ": a focal length in pixels must be > 0");
    }
  }
}

std::vector<CameraEntry> ListCameras(const std::string& path) {
  std::unique_ptr<xmlDoc, XmlDocFree> doc(xmlReadFile(
      path.c_str(), nullptr, XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING));
  if (!doc) {
    const xmlError* error = xmlGetLastError();
    std::string reason =
        error != nullptr && error->message != nullptr ? Trimmed(error->message) : "not well-formed";
    if (error != nullptr) reason += " at line " + std::to_string(error->line);
    throw std::runtime_error("camera file '" + path + "' is not valid XML: " + reason);
  }
  std::vector<CameraEntry> cameras;
  const xmlNode* root = xmlDocGetRootElement(doc.get());
  for (const xmlNode* node = root ? root->children : nullptr; node != nullptr; node = node->next) {
    if (Named(node, "camera")) cameras.push_back(ReadEntry(node));
  }
  return cameras;
}

const CameraEntry& ChooseCamera(const std::vector<CameraEntry>& cameras, const std::string& path,
                                const std::string& camera_name) {
  if (cameras.empty()) throw std::runtime_error("camera file '" + path + "' has no <camera>");
  if (camera_name.empty()) return cameras.front();
  std::string names;
  for (const CameraEntry& entry : cameras) {
    if (entry.name == camera_name) return entry;
    names += (names.empty() ? "'" : ", '") + entry.name + "'";
  }
  throw std::runtime_error("camera file '" + path + "' has no camera named '" + camera_name +
                           "' (cameras: " + names + ")");
}

std::string Extension(const std::string& path) {
  return Lowercase(std::filesystem::path(path).extension().string());
}

CameraFile LoadYamlCameraFile(const std::string& path, const std::string& camera_name) {
  const YamlCamera read = ReadYamlCamera(path);
  if (!camera_name.empty() && camera_name != read.name) {
    throw std::runtime_error(
        "camera file '" + path + "' holds " +
        (read.ros ? "the camera '" + read.name + "'" : "one camera, without a name") + ", not '" +
        camera_name + "' (a camera's name picks one of a ViSP camera XML's cameras)");
  }
  CameraFile result;
  result.camera = read.lens;
  result.name = read.name;
  result.width = read.width;
  result.height = read.height;
  result.format = read.ros ? CameraFileFormat::kRosCameraInfo : CameraFileFormat::kOpenCvYaml;
  return result;
}

CameraFile LoadViSPCameraFile(const std::string& path, const std::string& camera_name) {
  const std::vector<CameraEntry> cameras = ListCameras(path);
  const CameraEntry& entry = ChooseCamera(cameras, path, camera_name);
  const std::string label = "camera '" + entry.name + "' in '" + path + "'";
  if (!entry.with_distortion && !entry.without_distortion) {
    throw std::runtime_error(label + " has no model of type " + kWithDistortion + " or " +
                             kWithoutDistortion);
  }
  const auto model = entry.with_distortion ? vpCameraParameters::perspectiveProjWithDistortion
                                           : vpCameraParameters::perspectiveProjWithoutDistortion;
  CheckModelFields(entry.with_distortion ? entry.with_fields : entry.without_fields, path,
                   entry.name, entry.with_distortion ? kWithDistortion : kWithoutDistortion);
  CameraFile result;
  int status = vpXmlParserCamera::SEQUENCE_ERROR;
  vpCameraParameters parsed;
  try {
    MuteStandardStreams mute;
    vpXmlParserCamera parser;
    status = parser.parse(parsed, path, entry.name, model, entry.width, entry.height);
  } catch (const vpException& error) {
    throw std::runtime_error("vpXmlParserCamera cannot read " + label + ": " + error.getMessage());
  }
  if (status != vpXmlParserCamera::SEQUENCE_OK) {
    throw std::runtime_error("vpXmlParserCamera cannot read " + label +
                             " (a model with missing parameters, or several cameras of that "
                             "name and image size)");
  }
  result.camera = parsed;
  if (!(result.camera.px() > 0.0 && result.camera.py() > 0.0)) {
    throw std::runtime_error(label + " has px or py <= 0");
  }
  result.name = entry.name;
  result.width = entry.width;
  result.height = entry.height;
  result.format = CameraFileFormat::kViSPXml;
  return result;
}

void SaveViSPCameraFile(const std::string& path, const vpCameraParameters& camera,
                        const std::string& name, unsigned int width, unsigned int height,
                        const std::vector<std::string>& comments) {
  // ViSP keeps the elements of its additional information: one <note> a comment.
  std::string info;
  for (const std::string& comment : comments) info += "<note>" + MarkupEscaped(comment) + "</note>";
  // vpXmlParserCamera::save adds to an existing file, so it writes a fresh temporary file
  // that then replaces `path`.
  const std::filesystem::path temp = TempPathFor(path);
  RemoveQuietly(temp);
  int status = vpXmlParserCamera::SEQUENCE_ERROR;
  {
    MuteStandardStreams mute;
    vpXmlParserCamera parser;
    status = parser.save(camera, temp.string(), name, width, height, info);
  }
  std::error_code error;
  if (status == vpXmlParserCamera::SEQUENCE_OK && std::filesystem::is_regular_file(temp)) {
    std::filesystem::rename(temp, path, error);
    if (!error) return;
  }
  RemoveQuietly(temp);
  throw std::runtime_error("cannot write camera file '" + path + "'" +
                           (error ? ": " + error.message() : std::string()));
}

// The image size a file's approximation is fitted over: the file's, else the one the
// principal point centres.
std::pair<int, int> ApproximationSize(const Lens& lens, unsigned int width, unsigned int height) {
  if (width > 0 && height > 0) return {static_cast<int>(width), static_cast<int>(height)};
  return {static_cast<int>(std::lround(2.0 * lens.u0() + 1.0)),
          static_cast<int>(std::lround(2.0 * lens.v0() + 1.0))};
}

std::string ApproximationNote(const Lens& lens, const Lens& written, int width, int height,
                              const std::string& what) {
  return what + " is the best approximation of the " + LensModelName(lens) + " lens over the " +
         std::to_string(width) + " x " + std::to_string(height) + " image: it misses it by up to " +
         Fixed(WorstIdealPixelDifference(lens, written, width, height), 2) + " px";
}

}  // namespace

std::string CameraFileFormatName(CameraFileFormat format) {
  switch (format) {
    case CameraFileFormat::kViSPXml:
      return "ViSP's camera XML";
    case CameraFileFormat::kOpenCvYaml:
      return "OpenCV's calibration YAML";
    case CameraFileFormat::kRosCameraInfo:
      return "ROS's camera_info YAML";
  }
  return "";
}

CameraFileFormat CameraFileFormatFor(const std::string& path, bool ros) {
  const std::string extension = Extension(path);
  if (extension == ".xml" && !ros) return CameraFileFormat::kViSPXml;
  if (extension == ".yaml" || extension == ".yml") {
    return ros ? CameraFileFormat::kRosCameraInfo : CameraFileFormat::kOpenCvYaml;
  }
  throw std::invalid_argument(
      "camera file '" + path + "': " +
      (ros ? std::string("ROS's camera_info is a .yaml or .yml file")
           : "the extension names the format: .xml (ViSP's camera XML) or .yaml / .yml "
             "(OpenCV's calibration YAML; ROS's camera_info when asked for)"));
}

CameraFile LoadCameraFile(const std::string& path, const std::string& camera_name) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error("camera file '" + path + "' does not exist or is not a file");
  }
  const std::string extension = Extension(path);
  if (extension == ".yaml" || extension == ".yml") return LoadYamlCameraFile(path, camera_name);
  if (extension == ".xml") return LoadViSPCameraFile(path, camera_name);
  throw std::runtime_error("camera file '" + path +
                           "': the extension names the format: .xml (ViSP's camera XML), "
                           ".yaml or .yml (OpenCV's calibration YAML or ROS's camera_info)");
}

std::optional<std::string> SaveCameraFile(const std::string& path, const Lens& camera,
                                          const std::string& name, unsigned int width,
                                          unsigned int height, CameraFileFormat format,
                                          const std::vector<std::string>& comments) {
  const auto [fit_width, fit_height] = ApproximationSize(camera, width, height);
  std::optional<std::string> note;
  if (format == CameraFileFormat::kViSPXml) {
    const vpCameraParameters visp = camera.ViSPCamera(fit_width, fit_height);
    if (camera.IsViSPApproximation()) {
      note = ApproximationNote(camera, visp, fit_width, fit_height,
                               "ViSP's camera XML holds one radial term each way: its kud, kdu");
    }
    SaveViSPCameraFile(path, visp, name, width, height, comments);
    return note;
  }
  const Lens opencv = camera.OpenCvCamera(fit_width, fit_height);
  if (camera.IsOpenCvApproximation()) {
    note = ApproximationNote(camera, opencv, fit_width, fit_height,
                             "the file's OpenCV model (k1, k2, k3 for ViSP's kdu)");
  }
  AtomicFile file(path);
  file.stream() << (format == CameraFileFormat::kRosCameraInfo
                        ? RosCameraInfoText(opencv, name, width, height, comments)
                        : OpenCvYamlText(opencv, width, height, comments));
  file.Commit();
  return note;
}

std::optional<std::string> SaveCameraFile(const std::string& path, const Lens& camera,
                                          const std::string& name, unsigned int width,
                                          unsigned int height) {
  return SaveCameraFile(path, camera, name, width, height, CameraFileFormatFor(path, false), {});
}

std::optional<std::string> CameraSizeMismatch(const CameraFile& camera, int width, int height,
                                              const std::string& source) {
  if (camera.width == 0 || camera.height == 0) return std::nullopt;
  if (static_cast<int>(camera.width) == width && static_cast<int>(camera.height) == height) {
    return std::nullopt;
  }
  return "camera '" + camera.name + "' is calibrated for " + std::to_string(camera.width) + "x" +
         std::to_string(camera.height) + " but '" + source + "' is " + std::to_string(width) + "x" +
         std::to_string(height);
}

}  // namespace oal
