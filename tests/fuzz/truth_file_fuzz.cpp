// The truth readers on arbitrary files: the CSV of lines and poses, a frame's truth JSON (its
// lines and its pose). A bad file is a std::exception with a message, never a crash.
#include <cstdint>
#include <exception>
#include <string>

#include "io/truth_file.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string csv = oal::fuzz::ScratchFile(data, size, ".csv");
  try {
    oal::LoadTruthCsvWithPoses(csv);
  } catch (const std::exception&) {
  }
  const std::string json = oal::fuzz::ScratchFile(data, size, ".json");
  try {
    oal::LoadTruthPoseJson(json);
  } catch (const std::exception&) {
  }
  try {
    oal::LoadTruthJson(json);
  } catch (const std::exception&) {
  }
  return 0;
}
