// The ViSP camera file reader (libxml2 to list the cameras, then vpXmlParserCamera) on
// arbitrary files: a bad one is a std::exception with a message, never a crash.
#include <cstdint>
#include <exception>
#include <string>

#include "io/camera_file.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = oal::fuzz::ScratchFile(data, size, ".xml");
  for (const char* name : {"", "Camera"}) {
    try {
      oal::LoadCameraFile(path, name);
    } catch (const std::exception&) {
    }
  }
  return 0;
}
