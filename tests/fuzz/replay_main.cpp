// A fuzz target without libFuzzer: runs LLVMFuzzerTestOneInput once on every file named on the
// command line (a directory: each file in it, in name order), as libFuzzer does when given
// files; with --mutations N, then on N mutants of them, a short deterministic fuzz run:
//   NAME [--mutations N] [--dict FILE] INPUT...
// Mutant k takes input k modulo their count and applies one to four of libFuzzer's simplest
// mutations (flip a bit, set a byte, insert or erase bytes, copy a chunk elsewhere, insert a
// dictionary word), drawn from k. ctest runs each target so in every build (the sanitizer
// build included: the CI's fuzz run); scripts/fuzz.sh builds the same targets with libFuzzer
// to search for new inputs guided by coverage.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

std::vector<fs::path> InputsOf(const fs::path& path) {
  if (!fs::is_directory(path)) return {path};
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(path)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

Bytes ReadBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The words of a libFuzzer dictionary: each line's text between its first and last quote, with
// \\, \" and \xNN unescaped; comments and blank lines skipped.
std::vector<Bytes> ReadDictionary(const fs::path& file) {
  std::vector<Bytes> words;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t open = line.find('"'), close = line.rfind('"');
    if (line.empty() || line[0] == '#' || open == std::string::npos || close <= open) continue;
    Bytes word;
    for (std::size_t i = open + 1; i < close; ++i) {
      if (line[i] == '\\' && i + 3 < close && line[i + 1] == 'x') {
        word.push_back(
            static_cast<std::uint8_t>(std::strtoul(line.substr(i + 2, 2).c_str(), nullptr, 16)));
        i += 3;
      } else if (line[i] == '\\' && i + 1 < close) {
        word.push_back(static_cast<std::uint8_t>(line[++i]));
      } else {
        word.push_back(static_cast<std::uint8_t>(line[i]));
      }
    }
    if (!word.empty()) words.push_back(word);
  }
  return words;
}

// splitmix64: a fixed, portable sequence.
std::uint64_t Next(std::uint64_t* state) {
  std::uint64_t z = (*state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

Bytes Mutant(Bytes data, const std::vector<Bytes>& dictionary, std::uint64_t seed) {
  std::uint64_t state = seed;
  const auto below = [&state](std::size_t n) { return n == 0 ? 0 : Next(&state) % n; };
  const std::size_t steps = 1 + below(4);
  for (std::size_t step = 0; step < steps; ++step) {
    const std::size_t at = below(data.size() + 1);
    switch (below(dictionary.empty() ? 6 : 7)) {
      case 0:  // flip a bit
        if (at < data.size()) data[at] ^= static_cast<std::uint8_t>(1u << below(8));
        break;
      case 1:  // set a byte, often to an edge value
        if (at < data.size()) {
          const std::uint8_t edges[] = {0, 1, 0x7F, 0x80, 0xFF, '\r', '\n', '-', '9'};
          data[at] =
              below(2) == 0 ? edges[below(sizeof edges)] : static_cast<std::uint8_t>(Next(&state));
        }
        break;
      case 2:  // insert random bytes
        data.insert(data.begin() + static_cast<std::ptrdiff_t>(at), 1 + below(8),
                    static_cast<std::uint8_t>(Next(&state)));
        break;
      case 3: {  // erase a run
        const std::size_t n = std::min(data.size() - std::min(at, data.size()), 1 + below(16));
        data.erase(data.begin() + static_cast<std::ptrdiff_t>(at),
                   data.begin() + static_cast<std::ptrdiff_t>(at + n));
        break;
      }
      case 4:    // copy a chunk elsewhere
      case 5: {  // (twice as likely: it builds long and repeated fields)
        if (data.empty()) break;
        const std::size_t from = below(data.size());
        const std::size_t n = std::min(data.size() - from, 1 + below(64));
        const Bytes chunk(data.begin() + static_cast<std::ptrdiff_t>(from),
                          data.begin() + static_cast<std::ptrdiff_t>(from + n));
        data.insert(data.begin() + static_cast<std::ptrdiff_t>(at), chunk.begin(), chunk.end());
        break;
      }
      default: {  // a dictionary word
        const Bytes& word = dictionary[below(dictionary.size())];
        data.insert(data.begin() + static_cast<std::ptrdiff_t>(at), word.begin(), word.end());
        break;
      }
    }
  }
  return data;
}

void Run(const Bytes& bytes) {
  LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
}

}  // namespace

int main(int argc, char** argv) {
  long mutations = 0;
  std::vector<Bytes> dictionary;
  std::vector<Bytes> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if ((arg == "--mutations" || arg == "--dict") && i + 1 == argc) {
      std::fprintf(stderr, "%s: %s needs a value\n", argv[0], arg.c_str());
      return 1;
    }
    if (arg == "--mutations") {
      mutations = std::strtol(argv[++i], nullptr, 10);
      continue;
    }
    if (arg == "--dict") {
      if (!fs::is_regular_file(argv[++i])) {
        std::fprintf(stderr, "%s: no dictionary '%s'\n", argv[0], argv[i]);
        return 1;
      }
      dictionary = ReadDictionary(argv[i]);
      continue;
    }
    if (!fs::exists(arg)) {
      std::fprintf(stderr, "%s: no such file or directory '%s'\n", argv[0], argv[i]);
      return 1;
    }
    for (const fs::path& file : InputsOf(arg)) inputs.push_back(ReadBytes(file));
  }
  for (const Bytes& input : inputs) Run(input);
  for (long k = 0; k < mutations && !inputs.empty(); ++k) {
    Run(Mutant(inputs[static_cast<std::size_t>(k) % inputs.size()], dictionary,
               static_cast<std::uint64_t>(k)));
  }
  std::printf("%zu inputs and %ld mutants run\n", inputs.size(), inputs.empty() ? 0 : mutations);
  return inputs.empty() ? 1 : 0;
}
