#include "print/target_svg.h"

#include <cstdio>
#include <sstream>

#include "base/format.h"

namespace oal {
namespace {

std::string Grey() {
  char text[16];
  const int level = static_cast<int>(kPageGrey * 255.0 + 0.5);
  std::snprintf(text, sizeof(text), "#%02x%02x%02x", level, level, level);
  return text;
}

std::string IdAndClass(const std::string& id, const std::string& klass) {
  std::string out;
  if (!id.empty()) out += "id=\"" + MarkupEscaped(id) + "\" ";
  if (!klass.empty()) out += "class=\"" + MarkupEscaped(klass) + "\" ";
  return out;
}

std::string TextSvg(const PageText& text) {
  std::string out = "    <text " + IdAndClass(text.id, text.klass) + "x=\"" +
                    FormatMm(text.at.x_mm) + "\" y=\"" + FormatMm(text.at.y_mm) +
                    "\" font-size=\"" + FormatMm(kPageTextMm) + "\"";
  if (text.angle_deg != 0.0) {
    out += " transform=\"rotate(" + FormatMm(text.angle_deg) + " " + FormatMm(text.at.x_mm) + " " +
           FormatMm(text.at.y_mm) + ")\"";
  }
  return out + ">" + MarkupEscaped(text.text) + "</text>\n";
}

std::string LineSvg(const PageLine& line) {
  return "    <line " + IdAndClass(line.id, line.klass) + "x1=\"" + FormatMm(line.a.x_mm) +
         "\" y1=\"" + FormatMm(line.a.y_mm) + "\" x2=\"" + FormatMm(line.b.x_mm) + "\" y2=\"" +
         FormatMm(line.b.y_mm) + "\" stroke=\"" + Grey() + "\" stroke-width=\"" +
         FormatMm(line.stroke_mm) + "\"/>\n";
}

// One group of grey marks.
void WriteGroup(const TargetPage& page, PageGroup group, const char* id, std::ostringstream* svg) {
  *svg << "  <g id=\"" << id << "\" fill=\"" << Grey()
       << "\" stroke=\"none\" stroke-linecap=\"butt\" font-family=\"sans-serif\" "
          "text-anchor=\"middle\">\n";
  for (const PageLine& line : page.lines) {
    if (line.group == group) *svg << LineSvg(line);
  }
  for (const PageText& text : page.texts) {
    if (text.group == group) *svg << TextSvg(text);
  }
  *svg << "  </g>\n";
}

}  // namespace

std::string TargetSvg(const TargetPage& page) {
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\""
      << FormatMm(page.page_width_mm) << "mm\" height=\"" << FormatMm(page.page_height_mm)
      << "mm\" viewBox=\"0 0 " << FormatMm(page.page_width_mm) << " "
      << FormatMm(page.page_height_mm) << "\">\n"
      << "  <title>oalservo target " << MarkupEscaped(page.target_name) << "</title>\n"
      << "  <desc>" << MarkupEscaped(page.description) << "</desc>\n"
      << "  <g id=\"stripes\" fill=\"#000000\" stroke=\"none\">\n";
  for (const PageStripe& stripe : page.stripes) {
    std::string points;
    for (const PagePoint& p : stripe.corners) {
      points += (points.empty() ? "" : " ") + FormatMm(p.x_mm) + "," + FormatMm(p.y_mm);
    }
    svg << "    <polygon class=\"stripe\" id=\"line-" << stripe.line << "\" points=\"" << points
        << "\"/>\n";
  }
  svg << "  </g>\n";
  WriteGroup(page, PageGroup::kLineNumbers, "line-numbers", &svg);
  WriteGroup(page, PageGroup::kLegend, "legend", &svg);
  WriteGroup(page, PageGroup::kScale, "scale", &svg);
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace oal
