// A rendered data set's folder, as `oalservo render` writes it and `detect`, `pose` and
// `evaluate` read it:
//
//   DIR/frame_0000.png    8-bit grey frame
//   DIR/frame_0000.json   ground truth (truth_file.h, FrameTruthJson)
//   DIR/camera.xml        the camera file of the frames: ViSP's XML for a pinhole or ViSP's
//   or camera.yaml        lens, OpenCV's calibration YAML for a lens in OpenCV's model
//   DIR/sequence.json     a sequence's summary, written last: its presence means complete
//
// written all or nothing: into a temporary sibling folder, moved into DIR at the end.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/json_io.h"
#include "scene/lived_in.h"
#include "scene/scene.h"
#include "scene/sequence.h"

namespace oal {

/// "frame_0007.png" for index 7 and extension ".png" (at least four digits).
std::string DatasetFrameName(int index, const char* extension);

/// Whether `file` is one of the files a data set's writer owns: frame_NNNN.png,
/// frame_NNNN.json, camera.xml, camera.yaml, target.yaml or sequence.json.
bool IsDatasetFile(const std::filesystem::path& file);

/// The name of a data set's camera file for `lens`: "camera.yaml" (OpenCV's calibration
/// YAML) for a lens in OpenCV's model, which ViSP's XML cannot hold, else "camera.xml".
std::string DatasetCameraName(const Lens& lens);

/// The camera file of the data set in `dir`: camera.xml or camera.yaml, whichever it has
/// (camera.xml when both); none when it has neither.
std::optional<std::filesystem::path> FindDatasetCamera(const std::filesystem::path& dir);

/// A data set's folder written all or nothing. The files go to a temporary sibling folder
/// `<DIR>.tmp-<pid>`, which Commit() moves into place (one rename when DIR does not exist;
/// else the data set files already in DIR are removed and the new ones moved in, other files
/// kept). Without Commit() (an error), the temporary folder and any parent folders created
/// for it are removed: nothing is left behind.
class StagedDataset {
 public:
  /// How messages name the folder and the permission to replace a data set, in the words the
  /// user gave them (e.g. "--out" and "--overwrite").
  struct Names {
    std::string folder;
    std::string overwrite;
  };

  /// Throws std::invalid_argument when `dir` is not a folder, or holds data set files and
  /// `overwrite` is false; std::runtime_error when the temporary folder cannot be made.
  StagedDataset(const std::string& dir, bool overwrite, Names names);
  ~StagedDataset();
  StagedDataset(const StagedDataset&) = delete;
  StagedDataset& operator=(const StagedDataset&) = delete;

  /// Where the files are written until Commit().
  const std::filesystem::path& dir() const { return temp_; }
  /// Moves the files into place: frames first, then camera.xml, then sequence.json.
  void Commit();

 private:
  // Removes the parent folders the constructor created, if they are (still) empty.
  void RemoveCreatedParents() noexcept;

  std::string name_;  // the folder as given, for messages
  Names names_;
  std::filesystem::path target_;   // absolute, no trailing separator
  std::filesystem::path temp_;     // <target>.tmp-<pid>
  std::filesystem::path created_;  // the outermost parent folder created; empty: none
  bool committed_ = false;
};

/// The frame's effects as JSON ("effects" of a sequence's frame): gain, offset, occluders, and
/// those of a lived-in scene when it has them (plane occluders, glares, motion blur, JPEG).
Json EffectsJson(const FrameEffects& effects);

/// Writes `dir`/DatasetCameraName(): `render`'s camera and image size, the camera named `name`.
void SaveDatasetCamera(const std::filesystem::path& dir, const RenderOptions& render,
                       const std::string& name);

/// Writes frame_NNNN.png and frame_NNNN.json into `dir`, each atomically.
void WriteDatasetFrame(const std::filesystem::path& dir, int index, const RenderedFrame& frame,
                       const Json& truth);

/// What a data set records of how it was made: the target's name, the seed, and the name the
/// camera file gives its camera.
struct DatasetLabels {
  std::string target;
  std::uint64_t seed = 0;
  std::string camera = "oal-render";
};

/// `count` frames of `renderer`'s scene from poses drawn by SamplePose(`sampling`) from
/// `labels.seed`, each with the lived-in conditions `events` draws for it (its truth then
/// records them and each line's occluded fraction), their truth and camera.xml, written into
/// `dir`. Throws what SamplePose and the writes throw.
void WriteRandomDataset(const SceneRenderer& renderer, const PoseSampling& sampling, int count,
                        const DatasetLabels& labels, const std::filesystem::path& dir,
                        const LivedInOptions& events = LivedInOptions());

/// The frames of `sequence` through `renderer`, their truth (with the sequence's name, each
/// frame's effects and each line's occluded fraction), camera.xml and sequence.json (last),
/// written into `dir`.
void WriteSequenceDataset(const Sequence& sequence, const std::string& kind_name,
                          const SceneRenderer& renderer, const DatasetLabels& labels,
                          const std::filesystem::path& dir);

}  // namespace oal
