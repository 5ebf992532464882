#include "io/rendered_dataset.h"

#include <algorithm>
#include <opencv2/core/mat.hpp>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "io/atomic_file.h"
#include "io/camera_file.h"
#include "io/truth_file.h"

namespace oal {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> DatasetFilesIn(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file() && IsDatasetFile(entry.path())) files.push_back(entry.path());
  }
  return files;
}

// "20 frames, camera.xml" for the data set files `files`; empty for none.
std::string DescribeDatasetFiles(const std::vector<fs::path>& files) {
  int frames = 0;
  std::string others;
  for (const fs::path& file : files) {
    const std::string name = file.filename().string();
    if (file.extension() == ".png") {
      ++frames;
    } else if (file.extension() != ".json" || name == "sequence.json") {
      others += ", " + name;
    }
  }
  if (frames == 0 && others.empty() && !files.empty()) return "frame_NNNN.json files";
  if (frames == 0) return others.empty() ? "" : others.substr(2);
  return std::to_string(frames) + (frames == 1 ? " frame" : " frames") + others;
}

// Noise seed of frame `index`: distinct per frame, a pure function of the data set's seed.
std::uint64_t NoiseSeed(std::uint64_t seed, int index) {
  return seed ^ (0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(index + 1));
}

Json OccluderJson(const Occluder& occluder) {
  const bool disc = occluder.shape == Occluder::Shape::kDisc;
  Json json{{"shape", disc ? "disc" : "rectangle"},
            {"centre", Json::array({occluder.centre_u_px, occluder.centre_v_px})}};
  if (disc) {
    json["radius_px"] = occluder.half_width_px;
  } else {
    json["size_px"] = Json::array({2.0 * occluder.half_width_px, 2.0 * occluder.half_height_px});
  }
  json["grey"] = occluder.grey;
  return json;
}

}  // namespace

void SaveDatasetCamera(const fs::path& dir, const RenderOptions& render, const std::string& name) {
  SaveCameraFile((dir / DatasetCameraName(render.camera)).string(), render.camera, name,
                 static_cast<unsigned int>(render.width), static_cast<unsigned int>(render.height));
}

std::string DatasetCameraName(const Lens& lens) {
  return lens.model() == Lens::Model::kOpenCV ? "camera.yaml" : "camera.xml";
}

std::optional<fs::path> FindDatasetCamera(const fs::path& dir) {
  for (const char* name : {"camera.xml", "camera.yaml"}) {
    if (fs::is_regular_file(dir / name)) return dir / name;
  }
  return std::nullopt;
}

std::string DatasetFrameName(int index, const char* extension) {
  std::string number = std::to_string(index);
  if (number.size() < 4) number.insert(0, 4 - number.size(), '0');
  return "frame_" + number + extension;
}

bool IsDatasetFile(const fs::path& file) {
  const std::string name = file.filename().string();
  if (name == "camera.xml" || name == "camera.yaml" || name == "sequence.json" ||
      name == "target.yaml") {
    return true;
  }
  const std::string stem = file.stem().string();
  const std::string extension = file.extension().string();
  return (extension == ".png" || extension == ".json") && stem.size() > 6 &&
         stem.compare(0, 6, "frame_") == 0 &&
         stem.find_first_not_of("0123456789", 6) == std::string::npos;
}

StagedDataset::StagedDataset(const std::string& dir, bool overwrite, Names names)
    : name_(dir), names_(std::move(names)) {
  const std::string label = names_.folder + " '" + name_ + "'";
  target_ = fs::absolute(dir).lexically_normal();
  if (!target_.has_filename()) target_ = target_.parent_path();  // "data/", "."
  if (fs::exists(target_) && !fs::is_directory(target_)) {
    throw std::invalid_argument(label + " exists and is not a folder");
  }
  if (fs::is_directory(target_) && !overwrite) {
    const std::string held = DescribeDatasetFiles(DatasetFilesIn(target_));
    if (!held.empty()) {
      throw std::invalid_argument(label + " already holds a rendered data set (" + held +
                                  "); pass " + names_.overwrite +
                                  " to replace it (other files in the folder are kept), or "
                                  "choose another folder");
    }
  }
  const fs::path parent = target_.parent_path();
  for (fs::path p = parent; !p.empty() && !fs::exists(p); p = p.parent_path()) created_ = p;
  std::error_code error;
  fs::create_directories(parent, error);
  temp_ = TempPathFor(target_);
  if (!error) fs::remove_all(temp_, error);  // a stale one of an earlier process of this pid
  if (!error) fs::create_directory(temp_, error);
  if (error) {
    RemoveCreatedParents();
    throw std::runtime_error("cannot create the folder '" + temp_.string() + "' for " + label +
                             ": " + error.message());
  }
}

StagedDataset::~StagedDataset() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(temp_, ignored);
  RemoveCreatedParents();
}

void StagedDataset::Commit() {
  if (!fs::exists(target_)) {
    fs::rename(temp_, target_);
  } else {
    for (const fs::path& old : DatasetFilesIn(target_)) fs::remove(old);
    std::vector<fs::path> files;
    for (const fs::directory_entry& entry : fs::directory_iterator(temp_)) {
      files.push_back(entry.path());
    }
    auto rank = [](const fs::path& file) {
      const std::string name = file.filename().string();
      return std::make_pair(name == "sequence.json"                           ? 2
                            : (name == "camera.xml" || name == "camera.yaml") ? 1
                                                                              : 0,
                            name);
    };
    std::sort(files.begin(), files.end(),
              [&](const fs::path& a, const fs::path& b) { return rank(a) < rank(b); });
    for (const fs::path& file : files) fs::rename(file, target_ / file.filename());
    fs::remove(temp_);
  }
  committed_ = true;
}

void StagedDataset::RemoveCreatedParents() noexcept {
  if (created_.empty()) return;
  std::error_code error;
  for (fs::path p = target_.parent_path(); !error; p = p.parent_path()) {
    fs::remove(p, error);
    if (p == created_) break;
  }
}

Json EffectsJson(const FrameEffects& effects) {
  Json occluders = Json::array();
  for (const Occluder& occluder : effects.occluders) occluders.push_back(OccluderJson(occluder));
  Json json{{"gain", effects.gain}, {"offset", effects.offset}, {"occluders", occluders}};
  if (!effects.plane_occluders.empty()) {
    Json on_plane = Json::array();
    for (const PlaneOccluder& o : effects.plane_occluders) {
      Json capsules = Json::array(), ellipses = Json::array();
      for (const PlaneOccluder::Capsule& c : o.capsules) {
        capsules.push_back(
            {{"from_m", {c.x1_m, c.y1_m}}, {"to_m", {c.x2_m, c.y2_m}}, {"radius_m", c.radius_m}});
      }
      for (const PlaneOccluder::Ellipse& e : o.ellipses) {
        ellipses.push_back({{"centre_m", {e.x_m, e.y_m}},
                            {"semi_axes_m", {e.semi_a_m, e.semi_b_m}},
                            {"angle_rad", e.angle_rad}});
      }
      on_plane.push_back({{"label", o.label},
                          {"capsules", capsules},
                          {"ellipses", ellipses},
                          {"grey", o.grey},
                          {"texture_grey", o.texture_grey},
                          {"shadow_darkness", o.shadow_darkness}});
    }
    json["plane_occluders"] = on_plane;
  }
  if (!effects.glares.empty()) {
    Json glares = Json::array();
    for (const Glare& g : effects.glares) {
      glares.push_back(
          {{"centre_m", {g.x_m, g.y_m}}, {"sigma_m", g.sigma_m}, {"peak_grey", g.peak_grey}});
    }
    json["glares"] = glares;
  }
  if (effects.motion_blur_px > 0.0) {
    json["motion_blur_px"] = effects.motion_blur_px;
    json["motion_blur_angle_rad"] = effects.motion_blur_angle_rad;
  }
  if (effects.jpeg_quality > 0) json["jpeg_quality"] = effects.jpeg_quality;
  if (effects.noise_sigma >= 0.0) json["noise_sigma"] = effects.noise_sigma;
  if (effects.blur_sigma_px >= 0.0) json["blur_sigma_px"] = effects.blur_sigma_px;
  return json;
}

void WriteDatasetFrame(const fs::path& dir, int index, const RenderedFrame& frame,
                       const Json& truth) {
  const cv::Mat image(static_cast<int>(frame.image.getHeight()),
                      static_cast<int>(frame.image.getWidth()), CV_8UC1, frame.image.bitmap);
  WritePng(dir / DatasetFrameName(index, ".png"), image);
  WriteFileAtomically(dir / DatasetFrameName(index, ".json"), truth.dump(2) + "\n");
}

void WriteRandomDataset(const SceneRenderer& renderer, const PoseSampling& sampling, int count,
                        const DatasetLabels& labels, const fs::path& dir,
                        const LivedInOptions& events) {
  const RenderOptions& render = renderer.options();
  SaveDatasetCamera(dir, render, labels.camera);
  std::uint64_t state = labels.seed;
  for (int i = 0; i < count; ++i) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    const std::uint64_t noise_seed = NoiseSeed(labels.seed, i);
    FrameEffects effects;
    DrawLivedIn(events, renderer.target(), labels.seed, i, &effects);
    const RenderedFrame frame = renderer.Render(cMo, noise_seed, effects);
    Json truth = FrameTruthJson(frame, i, DatasetFrameName(i, ".png"), labels.target, labels.seed,
                                noise_seed, render.camera, render.width, render.height);
    if (events.Any()) {
      for (std::size_t l = 0; l < frame.truth.size(); ++l) {
        truth["lines"][l]["occluded_fraction"] = frame.truth[l].occluded_fraction;
      }
      truth["effects"] = EffectsJson(effects);
    }
    WriteDatasetFrame(dir, i, frame, truth);
  }
}

void WriteSequenceDataset(const Sequence& sequence, const std::string& kind_name,
                          const SceneRenderer& renderer, const DatasetLabels& labels,
                          const fs::path& dir) {
  const RenderOptions& render = renderer.options();
  SaveDatasetCamera(dir, render, labels.camera);
  const int count = static_cast<int>(sequence.frames.size());
  for (int i = 0; i < count; ++i) {
    const SequenceFrame& step = sequence.frames[static_cast<std::size_t>(i)];
    const RenderedFrame frame = renderer.Render(step.cMo, step.noise_seed, step.effects);
    Json truth = FrameTruthJson(frame, i, DatasetFrameName(i, ".png"), labels.target, labels.seed,
                                step.noise_seed, render.camera, render.width, render.height);
    for (std::size_t l = 0; l < frame.truth.size(); ++l) {
      truth["lines"][l]["occluded_fraction"] = frame.truth[l].occluded_fraction;
    }
    truth["sequence"] = kind_name;
    truth["effects"] = EffectsJson(step.effects);
    WriteDatasetFrame(dir, i, frame, truth);
  }
  const Json summary{
      {"kind", kind_name},
      {"seed", labels.seed},
      {"count", count},
      {"target", labels.target},
      {"description", sequence.description},
      {"camera", CameraJson(render.camera, render.width, render.height)},
      {"noise_sigma", render.noise_sigma},
      {"blur_sigma_px", render.blur_sigma_px},
      {"illumination_gradient", render.illumination_gradient},
      {"gradient_angle_rad", render.gradient_angle_rad},
      {"frames", DatasetFrameName(0, ".png") + " ... " + DatasetFrameName(count - 1, ".png")}};
  WriteFileAtomically(dir / "sequence.json", summary.dump(2) + "\n");
}

}  // namespace oal
