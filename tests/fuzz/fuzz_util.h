// What the fuzz targets share: a scratch file for readers that take a path.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

namespace oal::fuzz {

/// `size` bytes written to a file of this process under $TMPDIR (else /tmp), named with
/// `extension` (readers choose by it); the same path on every call, overwritten.
inline std::string ScratchFile(const std::uint8_t* data, std::size_t size,
                               const std::string& extension) {
  const char* dir = std::getenv("TMPDIR");
  const std::string path = std::string(dir != nullptr && *dir != '\0' ? dir : "/tmp") +
                           "/oal_fuzz_" + std::to_string(::getpid()) + extension;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace oal::fuzz
