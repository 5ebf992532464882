// The YAML configuration reader on arbitrary text: every bad file is a std::runtime_error or
// std::invalid_argument for the user (main() prints it), never a crash or another exception.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "app/config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    oal::ParseConfig(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
