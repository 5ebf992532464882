#include "print/target_pdf.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <memory>
#include <stdexcept>

#include "base/angles.h"

namespace oal {
namespace {

constexpr double kPointsPerMm = 72.0 / 25.4;

struct SurfaceDeleter {
  void operator()(cairo_surface_t* surface) const { cairo_surface_destroy(surface); }
};
struct ContextDeleter {
  void operator()(cairo_t* context) const { cairo_destroy(context); }
};

cairo_status_t Append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

void Require(cairo_status_t status, const char* what) {
  if (status != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(std::string("cannot draw the target's PDF: ") + what + ": " +
                             cairo_status_to_string(status));
  }
}

void DrawStripes(const TargetPage& page, cairo_t* cr) {
  cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
  for (const PageStripe& stripe : page.stripes) {
    cairo_move_to(cr, stripe.corners[0].x_mm, stripe.corners[0].y_mm);
    for (std::size_t i = 1; i < stripe.corners.size(); ++i) {
      cairo_line_to(cr, stripe.corners[i].x_mm, stripe.corners[i].y_mm);
    }
    cairo_close_path(cr);
    cairo_fill(cr);
  }
}

void DrawMarks(const TargetPage& page, cairo_t* cr) {
  cairo_set_source_rgb(cr, kPageGrey, kPageGrey, kPageGrey);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
  for (const PageLine& line : page.lines) {
    cairo_set_line_width(cr, line.stroke_mm);
    cairo_move_to(cr, line.a.x_mm, line.a.y_mm);
    cairo_line_to(cr, line.b.x_mm, line.b.y_mm);
    cairo_stroke(cr);
  }
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, kPageTextMm);
  for (const PageText& text : page.texts) {
    cairo_text_extents_t extents;
    cairo_text_extents(cr, text.text.c_str(), &extents);
    cairo_save(cr);
    // As the SVG's text-anchor="middle": `at` is the middle of the baseline.
    cairo_translate(cr, text.at.x_mm, text.at.y_mm);
    cairo_rotate(cr, text.angle_deg * kRadPerDeg);
    cairo_move_to(cr, -0.5 * extents.x_advance, 0.0);
    cairo_show_text(cr, text.text.c_str());
    cairo_restore(cr);
  }
}

}  // namespace

std::string TargetPdf(const TargetPage& page) {
  std::string pdf;
  {
    const std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
        cairo_pdf_surface_create_for_stream(&Append, &pdf, page.page_width_mm * kPointsPerMm,
                                            page.page_height_mm * kPointsPerMm));
    Require(cairo_surface_status(surface.get()), "the PDF surface");
    const std::string title = "oalservo target " + page.target_name + ", " + page.page;
    cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_TITLE, title.c_str());
    cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_SUBJECT,
                                   page.description.c_str());
    cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_CREATOR, "oalservo target");
    const std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
    cairo_scale(cr.get(), kPointsPerMm, kPointsPerMm);  // drawn in millimetres
    DrawStripes(page, cr.get());
    DrawMarks(page, cr.get());
    cairo_show_page(cr.get());
    Require(cairo_status(cr.get()), "drawing");
    cairo_surface_finish(surface.get());
    Require(cairo_surface_status(surface.get()), "finishing the file");
  }
  return pdf;
}

}  // namespace oal
