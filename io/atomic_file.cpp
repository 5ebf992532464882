#include "io/atomic_file.h"

#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <system_error>

namespace oal {

namespace fs = std::filesystem;

std::filesystem::path TempPathFor(const fs::path& target) {
  fs::path temp = target;
  temp += ".tmp-" + std::to_string(static_cast<long>(::getpid()));
  return temp;
}

void RemoveQuietly(const fs::path& path) noexcept {
  std::error_code ignored;
  fs::remove(path, ignored);
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)), temp_(TempPathFor(target_)) {
  stream_.open(temp_, std::ios::binary | std::ios::trunc);
  if (!stream_) {
    throw std::runtime_error("cannot write '" + temp_.string() +
                             "' (does the directory exist and is it writable?)");
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  RemoveQuietly(temp_);
}

void AtomicFile::Commit() {
  stream_.flush();
  stream_.close();
  if (stream_.fail()) throw std::runtime_error("error while writing '" + temp_.string() + "'");
  std::error_code error;
  fs::rename(temp_, target_, error);
  if (error) {
    throw std::runtime_error("cannot rename '" + temp_.string() + "' to '" + target_.string() +
                             "': " + error.message());
  }
  committed_ = true;
}

void WriteFileAtomically(const fs::path& target, const std::string& bytes) {
  AtomicFile file(target);
  file.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  file.Commit();
}

void WriteFileAtomically(const fs::path& target, const std::vector<unsigned char>& bytes) {
  AtomicFile file(target);
  file.stream().write(reinterpret_cast<const char*>(bytes.data()),
                      static_cast<std::streamsize>(bytes.size()));
  file.Commit();
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) {
    throw std::runtime_error("cannot encode a PNG for '" + path.string() + "'");
  }
  WriteFileAtomically(path, bytes);
}

void CheckOutputFile(const std::filesystem::path& target) {
  const std::filesystem::path parent = target.parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw std::invalid_argument("output directory '" + parent.string() + "' does not exist");
  }
  if (std::filesystem::is_directory(target)) {
    throw std::invalid_argument("output '" + target.string() + "' is a directory, not a file");
  }
}

void PrepareOutputFile(const std::filesystem::path& target, const std::string& option) {
  if (target.has_parent_path()) {
    std::error_code error;
    std::filesystem::create_directories(target.parent_path(), error);
    if (error) {
      throw std::runtime_error(option + " " + target.string() + ": cannot create directory " +
                               target.parent_path().string() + ": " + error.message());
    }
  }
  CheckOutputFile(target);
}

}  // namespace oal
