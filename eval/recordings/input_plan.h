// Which inputs `oalservo evaluate` (eval/recordings/evaluate.h) reads, and what each is called: the
// directories expanded into their videos and image sequences, each named after itself,
// uniquely; the shard a run takes.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace oal {

/// "I/N" -> (I, N); throws std::invalid_argument unless 0 <= I < N.
std::pair<int, int> ParseShard(const std::string& text);

/// One input after the expansion of directories.
struct PlannedInput {
  std::string spec;  ///< what OpenImageSource opens
  std::string name;  ///< its output directory's name, unique in the plan
};

struct InputPlan {
  std::vector<PlannedInput> inputs;  ///< every input, before sharding
  /// Entries of input directories that are no input (companion files left out), and input
  /// directories holding no input.
  std::vector<std::string> skipped;
};

/// Expands `inputs` (file comment) and names them. Inputs that do not exist stay in the
/// plan (they fail when evaluated, without stopping the others).
InputPlan PlanInputs(const std::vector<std::string>& inputs);

/// Why a plan has no input: the inputs given and what their directories held.
std::string NoInputsMessage(const std::vector<std::string>& inputs, const InputPlan& plan);

}  // namespace oal
