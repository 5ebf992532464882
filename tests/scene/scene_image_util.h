// Helpers for the scene tests that handle whole images: a checksum for byte-identity checks and
// a reader for the binary PGM files of ViSP's test images (the scene library reads no files).
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpImage.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

namespace oal::testing {

/// FNV-1a over `size` bytes, continuing from `hash`.
inline std::uint64_t Fnv1a(const void* data, std::size_t size,
                           std::uint64_t hash = 0xcbf29ce484222325ull) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash = (hash ^ bytes[i]) * 0x100000001b3ull;
  }
  return hash;
}

/// Checksum of an image's size and pixels.
inline std::uint64_t ImageChecksum(const vpImage<unsigned char>& image) {
  const std::uint32_t size[2] = {image.getWidth(), image.getHeight()};
  return Fnv1a(image.bitmap, image.getSize(), Fnv1a(size, sizeof(size)));
}

/// Checksum of the 16 doubles of a pose, continuing from `hash`.
inline std::uint64_t PoseChecksum(const vpHomogeneousMatrix& cMo, std::uint64_t hash) {
  for (unsigned r = 0; r < 4; ++r) {
    for (unsigned c = 0; c < 4; ++c) {
      const double value = cMo[r][c];
      hash = Fnv1a(&value, sizeof(value), hash);
    }
  }
  return hash;
}

/// A binary 8-bit PGM (P5) file; nullptr when it cannot be read.
inline std::shared_ptr<const vpImage<unsigned char>> ReadPgm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  in >> magic;
  if (!in || magic != "P5") return nullptr;
  int values[3] = {0, 0, 0};  // width, height, maximum
  for (int& value : values) {
    in >> std::ws;
    while (in.peek() == '#') {
      std::string comment;
      std::getline(in, comment);
      in >> std::ws;
    }
    in >> value;
  }
  in.get();  // the single whitespace before the pixels
  if (!in || values[0] <= 0 || values[1] <= 0 || values[2] != 255) return nullptr;
  auto image = std::make_shared<vpImage<unsigned char>>(static_cast<unsigned>(values[1]),
                                                        static_cast<unsigned>(values[0]));
  in.read(reinterpret_cast<char*>(image->bitmap), static_cast<std::streamsize>(image->getSize()));
  if (!in) return nullptr;
  return image;
}

}  // namespace oal::testing
