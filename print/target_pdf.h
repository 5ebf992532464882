// A target's page (print/target_page.h) as a one-page PDF, drawn by cairo: the page exactly
// the sheet's size, true scale (print at 100 %, "actual size"), the stripes as filled black
// paths, the grey marks as vectors and text. The title names the target and the page.
#pragma once

#include <string>

#include "print/target_page.h"

namespace oal {

/// The PDF document of `page`, as bytes. Throws std::runtime_error if cairo fails.
std::string TargetPdf(const TargetPage& page);

}  // namespace oal
