// The printed target as real renderers draw it: the SVG through rsvg-convert and through
// ImageMagick's own SVG renderer, the PDF through poppler's pdftoppm. Each stripe's ink is
// measured across it at several places (its width, the ink's total, and its centre, the ink's
// centroid) and compared with the target's lines: within 0.2 mm. A renderer that is not
// installed skips its part, saying which package has it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "print/target_page.h"
#include "print/target_pdf.h"
#include "print/target_svg.h"
#include "target/line_target.h"
#include "tests/test_util.h"

namespace oal {
namespace {

constexpr double kDpi = 300.0;  // 0.085 mm a pixel
constexpr double kMmPerInch = 25.4;
constexpr double kToleranceMm = 0.2;

bool HasProgram(const std::string& name) {
  return std::system(("command -v " + name + " >/dev/null 2>&1").c_str()) == 0;
}

struct Renderer {
  const char* name;
  const char* program;
  const char* package;
  const char* input;  // "svg" or "pdf"
  // The shell command that renders `in` to `out` (a PNG or PGM file) at kDpi.
  std::string (*command)(const std::string& in, const std::string& out);
};

const Renderer kRenderers[] = {
    {"rsvg-convert", "rsvg-convert", "librsvg2-bin", "svg",
     [](const std::string& in, const std::string& out) {
       return "rsvg-convert -d 300 -p 300 -b white '" + in + "' -o '" + out + ".png'";
     }},
    {"ImageMagick's SVG renderer", "convert", "imagemagick (and gsfonts)", "svg",
     [](const std::string& in, const std::string& out) {
       return "convert -density 300 'msvg:" + in +
              "' -background white -flatten -colorspace "
              "gray '" +
              out + ".png'";
     }},
    {"pdftoppm", "pdftoppm", "poppler-utils", "pdf",
     [](const std::string& in, const std::string& out) {
       return "pdftoppm -r 300 -gray -singlefile '" + in + "' '" + out + "'";
     }},
};

// The image's grey at page position (x, y) mm, bilinear between pixel centres; white outside.
double GreyAt(const cv::Mat& image, double x_mm, double y_mm) {
  const double u = x_mm * kDpi / kMmPerInch - 0.5, v = y_mm * kDpi / kMmPerInch - 0.5;
  const int u0 = static_cast<int>(std::floor(u)), v0 = static_cast<int>(std::floor(v));
  const double fu = u - u0, fv = v - v0;
  const auto at = [&](int c, int r) {
    if (c < 0 || r < 0 || c >= image.cols || r >= image.rows) return 255.0;
    return static_cast<double>(image.at<std::uint8_t>(r, c));
  };
  return (1 - fv) * ((1 - fu) * at(u0, v0) + fu * at(u0 + 1, v0)) +
         fv * ((1 - fu) * at(u0, v0 + 1) + fu * at(u0 + 1, v0 + 1));
}

struct Across {
  double width_mm = 0.0, centre_mm = 0.0;  // centre: from the centre line, along `normal`
};

// The ink across a stripe at `at` (page mm), along `normal`, out to `reach` mm each side.
Across InkAcross(const cv::Mat& image, double at_x, double at_y, double nx, double ny,
                 double reach) {
  constexpr double kStepMm = 0.01;
  Across across;
  double moment = 0.0;
  for (double s = -reach; s <= reach; s += kStepMm) {
    const double ink = 1.0 - GreyAt(image, at_x + s * nx, at_y + s * ny) / 255.0;
    across.width_mm += ink * kStepMm;
    moment += s * ink * kStepMm;
  }
  across.centre_mm = across.width_mm > 0.0 ? moment / across.width_mm : 0.0;
  return across;
}

// Every stripe of `target` on the rendered page measured at a few places along it, away from
// the other stripes: width and centre within kToleranceMm of the target's.
// Returns the largest difference seen, mm.
double ExpectStripesInked(const cv::Mat& image, const LineTarget& target, const TargetPage& page) {
  const double cx = 0.5 * page.page_width_mm, cy = 0.5 * page.page_height_mm;
  const auto on_page = [&](double x_m, double y_m) {
    return page.turned ? cv::Point2d(cx - 1000.0 * y_m, cy + 1000.0 * x_m)
                       : cv::Point2d(cx + 1000.0 * x_m, cy + 1000.0 * y_m);
  };
  int measured = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < target.lines.size(); ++i) {
    const TargetLine& line = target.lines[i];
    const cv::Point2d a = on_page(line.x1_m, line.y1_m), b = on_page(line.x2_m, line.y2_m);
    const double length = cv::norm(b - a);
    const cv::Point2d along = (b - a) / length, normal(-along.y, along.x);
    const double half = 500.0 * line.width_m;
    for (const double t : {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9}) {
      const cv::Point2d at = a + t * length * along;
      // Away from every other stripe (its ink would count), by its half width and 3 mm.
      bool clear = true;
      for (std::size_t j = 0; j < target.lines.size() && clear; ++j) {
        if (j == i) continue;
        const TargetLine& other = target.lines[j];
        const cv::Point2d p = on_page(other.x1_m, other.y1_m), q = on_page(other.x2_m, other.y2_m);
        const cv::Point2d d = (q - p) / cv::norm(q - p);
        const double distance = std::fabs((at - p).cross(d));
        clear = distance > 500.0 * other.width_m + half + 3.0;
      }
      if (!clear) continue;
      const Across ink = InkAcross(image, at.x, at.y, normal.x, normal.y, half + 3.0);
      EXPECT_NEAR(ink.width_mm, 2.0 * half, kToleranceMm)
          << "line " << i + 1 << " at " << t << " of its length";
      EXPECT_NEAR(ink.centre_mm, 0.0, kToleranceMm)
          << "line " << i + 1 << " at " << t << " of its length";
      worst = std::max({worst, std::fabs(ink.width_mm - 2.0 * half), std::fabs(ink.centre_mm)});
      ++measured;
    }
  }
  EXPECT_GE(measured, static_cast<int>(2 * target.lines.size()));
  return worst;
}

TEST(TargetRendered, EveryRendererInksTheStripesWhereTheTargetHasThem) {
  test::TestDir dir;
  struct Case {
    LineTarget target;
    const char* page;
    bool landscape;
  };
  const Case cases[] = {{FourLineA3Target(), "a3", false},
                        {FourLineA4Target(), "a4", true},
                        {FourLineLetterTarget(), "letter", false}};
  int rendered = 0;
  std::string skipped;
  for (const Case& c : cases) {
    const TargetPage page = DrawTargetPage(c.target, c.page, c.landscape);
    const std::string base = dir / (c.target.name + (c.landscape ? "-landscape" : ""));
    test::WriteText(base + ".svg", TargetSvg(page));
    test::WriteText(base + ".pdf", TargetPdf(page));
    for (const Renderer& renderer : kRenderers) {
      SCOPED_TRACE(c.target.name + " on " + page.page + " through " + renderer.name);
      if (!HasProgram(renderer.program)) {
        skipped += std::string(skipped.empty() ? "" : "; ") + renderer.name + " (" +
                   renderer.program + ", Debian's " + renderer.package + ")";
        continue;
      }
      const std::string out = base + "-" + renderer.program;
      const std::string command = renderer.command(base + "." + renderer.input, out);
      ASSERT_EQ(std::system((command + " 2>'" + out + ".err'").c_str()), 0)
          << command << ": " << test::ReadText(out + ".err");
      const std::string file = std::filesystem::exists(out + ".png") ? out + ".png" : out + ".pgm";
      const cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
      ASSERT_FALSE(image.empty()) << command << " wrote no image";
      // True scale: the page's size at kDpi, within the tolerance (and a pixel's rounding).
      const double tolerance_px = kToleranceMm * kDpi / kMmPerInch + 1.0;
      EXPECT_NEAR(image.cols, page.page_width_mm * kDpi / kMmPerInch, tolerance_px);
      EXPECT_NEAR(image.rows, page.page_height_mm * kDpi / kMmPerInch, tolerance_px);
      std::cout << c.target.name << " on " << page.page << " through " << renderer.name
                << ": the stripes' width and centre within "
                << ExpectStripesInked(image, c.target, page) << " mm\n";
      ++rendered;
    }
  }
  if (!skipped.empty()) {
    if (rendered == 0) GTEST_SKIP() << "no renderer installed: " << skipped;
    std::cout << "not installed, skipped: " << skipped << '\n';
  }
}

}  // namespace
}  // namespace oal
