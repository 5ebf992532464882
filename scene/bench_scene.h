// A sheet lying on a bench as the accuracy evaluations, benchmarks and tests render it and
// view it: light falling off towards the image's corners, the sheet's soft shadow, paper
// texture, its printed marks, other printed pages and tools around it, and the camera poses a
// sheet is evaluated from.
#pragma once

#include <cstdint>

#include "scene/scene.h"

namespace oal {

/// Sets `render`'s fall-off, shadow, paper, annotations and clutter to the bench's (vignetting
/// 0.3, shadow 0.3, texture 3 grey levels, the marks printed, two pages and four tools within
/// 25 cm of the sheet, laid out from `scene_seed`); camera, noise, blur and surface are left
/// as they are. eval/rendered/rendered_frames.cpp's BenchScene() is the same scene as a config.
void DressAsBench(RenderOptions* render, std::uint64_t scene_seed);

/// Whether `target` is a sheet (both sides at most 1 m) rather than the paper's 2 m board.
bool IsSheet(const LineTarget& target);

/// A sheet from the near to the far end of its range (A3 0.3-0.85 m, A4 and letter
/// 0.25-0.6 m, another sheet scaled from A3 by its width): tilt up to 30 deg, any roll, the
/// four crossings 10 px inside the image, the optical axis within 0.1 m of the sheet's
/// centre (so that the sheet is often partly out of view).
PoseSampling SheetSampling(const LineTarget& target);

}  // namespace oal
