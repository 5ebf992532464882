// A sheet lying on a bench as the accuracy evaluations, benchmarks and tests render it:
// light falling off towards the image's corners, the sheet's soft shadow, paper texture, its
// printed marks, and other printed pages and tools around it.
#pragma once

#include <cstdint>

#include "scene/scene.h"

namespace oal {

/// Sets `render`'s fall-off, shadow, paper, annotations and clutter to the bench's (vignetting
/// 0.3, shadow 0.3, texture 3 grey levels, the marks printed, two pages and four tools within
/// 25 cm of the sheet, laid out from `scene_seed`); camera, noise, blur and surface are left
/// as they are. app/accuracy_frames.cpp's BenchScene() is the same scene as a config.
void DressAsBench(RenderOptions* render, std::uint64_t scene_seed);

}  // namespace oal
