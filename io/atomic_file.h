// Output files that appear whole or not at all: everything is written to a temporary file
// next to the target, `<target>.tmp-<pid>`, and renamed onto the target at the end. A crash
// or an error leaves no partial file under the target's name (rename is atomic within one
// file system, which is why the temporary file sits in the same directory).
#pragma once

#include <filesystem>
#include <fstream>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

namespace oal {

/// `<target>.tmp-<pid>`: the temporary name used for `target`.
std::filesystem::path TempPathFor(const std::filesystem::path& target);

/// A file being written under its temporary name. The destructor removes the temporary file
/// unless Commit() succeeded, so an exception anywhere leaves nothing behind.
class AtomicFile {
 public:
  /// Opens the temporary file for writing (binary); throws std::runtime_error if it cannot.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return stream_; }
  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temp_path() const { return temp_; }

  /// Flushes, closes and renames onto the target; throws std::runtime_error on a write error
  /// (disk full...), after which the destructor still removes the temporary file.
  void Commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  std::ofstream stream_;
  bool committed_ = false;
};

/// Runs `write(stream, interactive)` on `target` written atomically (the file appears only
/// if `write` returns), or on `console` with interactive = true when `target` is empty, so
/// that a caller can flush each record for a live reader.
template <typename Write>
void WriteToFileOrConsole(const std::string& target, std::ostream& console, Write write) {
  if (target.empty()) {
    write(console, true);
    return;
  }
  AtomicFile file(target);  // removed on any exception in `write`
  write(file.stream(), false);
  file.Commit();
}

/// Throws std::invalid_argument when `target` cannot be an output file: its directory does
/// not exist, or it is itself a directory. Call before any work, so nothing is half done.
void CheckOutputFile(const std::filesystem::path& target);

/// Creates the directories above `target`, an output file the user named with `option`
/// (e.g. "--out"), then CheckOutputFile(target). Throws std::runtime_error naming the option
/// when a directory cannot be created.
void PrepareOutputFile(const std::filesystem::path& target, const std::string& option);

/// Writes `bytes` to `target` atomically.
void WriteFileAtomically(const std::filesystem::path& target, const std::string& bytes);
void WriteFileAtomically(const std::filesystem::path& target,
                         const std::vector<unsigned char>& bytes);

/// Encodes `image` as PNG and writes it to `path` atomically.
void WritePng(const std::filesystem::path& path, const cv::Mat& image);

/// Removes `path` if it exists, ignoring errors (for cleanup paths that must not throw).
void RemoveQuietly(const std::filesystem::path& path) noexcept;

}  // namespace oal
