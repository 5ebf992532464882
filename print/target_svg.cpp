#include "print/target_svg.h"

#include <cstdio>
#include <sstream>

#include "base/format.h"

namespace oal {
namespace {

// Millimetres with at most 4 decimals, trailing zeros dropped ("12.5", "-80", "0.0125").
std::string Mm(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.4f", value);
  std::string out = text;
  while (out.back() == '0') out.pop_back();
  if (out.back() == '.') out.pop_back();
  if (out == "-0") out = "0";
  return out;
}

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
  std::string out = "    <text " + IdAndClass(text.id, text.klass) + "x=\"" + Mm(text.at.x_mm) +
                    "\" y=\"" + Mm(text.at.y_mm) + "\" font-size=\"" + Mm(kPageTextMm) + "\"";
  if (text.angle_deg != 0.0) {
    out += " transform=\"rotate(" + Mm(text.angle_deg) + " " + Mm(text.at.x_mm) + " " +
           Mm(text.at.y_mm) + ")\"";
  }
  return out + ">" + MarkupEscaped(text.text) + "</text>\n";
}

std::string LineSvg(const PageLine& line) {
  return "    <line " + IdAndClass(line.id, line.klass) + "x1=\"" + Mm(line.a.x_mm) + "\" y1=\"" +
         Mm(line.a.y_mm) + "\" x2=\"" + Mm(line.b.x_mm) + "\" y2=\"" + Mm(line.b.y_mm) +
         "\" stroke=\"" + Grey() + "\" stroke-width=\"" + Mm(line.stroke_mm) + "\"/>\n";
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
      << Mm(page.page_width_mm) << "mm\" height=\"" << Mm(page.page_height_mm)
      << "mm\" viewBox=\"0 0 " << Mm(page.page_width_mm) << " " << Mm(page.page_height_mm)
      << "\">\n"
      << "  <title>oalservo target " << MarkupEscaped(page.target_name) << "</title>\n"
      << "  <desc>" << MarkupEscaped(page.description) << "</desc>\n"
      << "  <g id=\"stripes\" fill=\"#000000\" stroke=\"none\">\n";
  for (const PageStripe& stripe : page.stripes) {
    std::string points;
    for (const PagePoint& p : stripe.corners) {
      points += (points.empty() ? "" : " ") + Mm(p.x_mm) + "," + Mm(p.y_mm);
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
