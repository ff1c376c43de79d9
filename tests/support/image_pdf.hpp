#pragma once
/// @file image_pdf.hpp
/// An image-only PDF, as every scanner and phone "scan to PDF" app writes: one page the size of the picture
/// at `dpi`, holding nothing but the JPEG (DCTDecode, grey), no text layer; or with a one-line text layer
/// that covers little of the page, as a scanner stamping its caption writes.

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace hk::test {

/// A PDF file of `objects` (object i + 1 is objects[i]; the first the catalog), with its cross-reference table.
inline std::string pdf_of_objects(const std::vector<std::string>& objects) {
  std::string out = "%PDF-1.4\n%\xe2\xe3\xcf\xd3\n";
  std::vector<std::size_t> offsets;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    offsets.push_back(out.size());
    out += std::to_string(i + 1) + " 0 obj\n" + objects[i] + "\nendobj\n";
  }
  const std::size_t xref = out.size();
  out += "xref\n0 " + std::to_string(objects.size() + 1) + "\n0000000000 65535 f \n";
  for (std::size_t off : offsets) {
    char line[24];
    std::snprintf(line, sizeof line, "%010zu 00000 n \n", off);
    out += line;
  }
  out += "trailer\n<< /Size " + std::to_string(objects.size() + 1) + " /Root 1 0 R >>\nstartxref\n" +
         std::to_string(xref) + "\n%%EOF\n";
  return out;
}

/// The bytes of a one-page PDF showing `jpeg` (a grey JPEG of width x height pixels) at `dpi`. A non-empty
/// `caption` (ASCII letters, digits and spaces) is added as invisible text (render mode 3, as OCR layers are
/// written) in 10 pt Helvetica near the bottom-left corner: a text layer of one short line.
inline std::string image_only_pdf(const std::vector<std::uint8_t>& jpeg, int width, int height, double dpi,
                                  const std::string& caption = {}) {
  const double w_pt = width * 72.0 / dpi, h_pt = height * 72.0 / dpi;
  char image[128];
  std::snprintf(image, sizeof image, "q %.3f 0 0 %.3f 0 0 cm /Im0 Do Q", w_pt, h_pt);
  const std::string content =
      std::string(image) + (caption.empty() ? "" : "\nBT /F1 10 Tf 3 Tr 20 20 Td (" + caption + ") Tj ET");
  char page[320];
  std::snprintf(
      page, sizeof page,
      "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 %.3f %.3f] /Contents 4 0 R /Resources << /XObject << /Im0 5 0 R >> "
      "/Font << /F1 6 0 R >> >> >>",
      w_pt, h_pt);
  const std::string image_head = "<< /Type /XObject /Subtype /Image /Width " + std::to_string(width) + " /Height " +
                                 std::to_string(height) +
                                 " /ColorSpace /DeviceGray /BitsPerComponent 8 /Filter /DCTDecode /Length " +
                                 std::to_string(jpeg.size()) + " >>\nstream\n";
  const std::vector<std::string> objects{
      "<< /Type /Catalog /Pages 2 0 R >>",
      "<< /Type /Pages /Count 1 /Kids [3 0 R] >>",
      page,
      "<< /Length " + std::to_string(content.size()) + " >>\nstream\n" + content + "\nendstream",
      image_head + std::string(jpeg.begin(), jpeg.end()) + "\nendstream",
      "<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>",
  };
  return pdf_of_objects(objects);
}

}  // namespace hk::test
