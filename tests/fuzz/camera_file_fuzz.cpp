// The camera file readers on arbitrary files, each input read as every format: ViSP's XML
// (libxml2 to list the cameras, then vpXmlParserCamera), OpenCV's calibration YAML and ROS's
// camera_info (yaml-cpp): a bad one is a std::exception with a message, never a crash.
#include <cstdint>
#include <exception>
#include <string>

#include "io/camera_file.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (const char* extension : {".xml", ".yaml"}) {
    const std::string path = oal::fuzz::ScratchFile(data, size, extension);
    for (const char* name : {"", "Camera"}) {
      try {
        oal::LoadCameraFile(path, name);
      } catch (const std::exception&) {
      }
    }
  }
  return 0;
}
