// A target's page (print/target_page.h) as an SVG document: 1 unit = 1 mm, the page's size
// in mm. Only filled polygons, lines and texts: no clipping, masks or filters, so that every
// renderer (browsers, rsvg, ImageMagick, Inkscape) draws it alike.
#pragma once

#include <string>

#include "print/target_page.h"

namespace oal {

/// The SVG document of `page`: the stripes (group "stripes", each polygon id "line-N"), then
/// the line numbers, the legend and the scale bar in their groups.
std::string TargetSvg(const TargetPage& page);

}  // namespace oal
