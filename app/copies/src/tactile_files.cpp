// A tactile graphic as SVG and BRF, and any of the three written to a file (tactile_output.hpp).
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "copies/tactile_output.hpp"
#include "hk/text.hpp"

namespace hk::app {
namespace {

std::string xml_escaped(std::string_view s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += static_cast<unsigned char>(c) < 0x20 ? ' ' : c;
    }
  }
  return out;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::string dash_array(LineStyle style) {
  switch (style) {
    case LineStyle::dashed:
      return " stroke-dasharray=\"6 3\"";
    case LineStyle::dotted:
      return " stroke-dasharray=\"1.5 2\"";
    case LineStyle::dash_dot:
      return " stroke-dasharray=\"6 3 1.5 3\"";
    case LineStyle::solid:
    case LineStyle::textured:
      return {};
  }
  return {};
}

std::string path_of(const TactileStroke& s) {
  std::string d;
  for (std::size_t i = 0; i < s.points_mm.size(); ++i)
    d += (i == 0 ? "M" : " L") + num(s.points_mm[i].x) + " " + num(s.points_mm[i].y);
  if (s.closed) d += " Z";
  return "<path d=\"" + d + "\"" + dash_array(s.style) + "/>";
}

std::string label_svg(const TactileLabel& l) {
  std::string out;
  if (!l.cells.empty())
    out += "<text class=\"braille\" x=\"" + num(l.at_mm.x) + "\" y=\"" + num(l.at_mm.y + 7.0) + "\">" +
           xml_escaped(l.cells) + "</text>";
  if (l.print_below && !l.print.empty())
    out += "<text class=\"print\" x=\"" + num(l.at_mm.x) + "\" y=\"" +
           num(l.at_mm.y + (l.cells.empty() ? 0.0 : kBrailleLinePitchMm) + 0.8 * kPrintTextMm) + "\">" +
           xml_escaped(l.print) + "</text>";
  return out;
}

/// BRF lines of `text` in braille, no longer than kBrfCellsPerLine, broken at blanks where it can.
void add_brf_lines(std::vector<std::string>& lines, const std::string& text, const std::string& language,
                   BrailleGrade grade) {
  std::string brf = brf_of(to_braille(text, language, grade));
  while (brf.size() > static_cast<std::size_t>(kBrfCellsPerLine)) {
    std::size_t cut = brf.rfind(' ', kBrfCellsPerLine);
    if (cut == std::string::npos || cut == 0) cut = kBrfCellsPerLine;
    lines.push_back(brf.substr(0, cut));
    brf.erase(0, cut == static_cast<std::size_t>(kBrfCellsPerLine) ? cut : cut + 1);
  }
  lines.push_back(brf);
}

}  // namespace

std::string tactile_svg(const TactileGraphic& g) {
  const double w = g.paper.width_mm,
               h = g.paper.height_mm * static_cast<double>(std::max<std::size_t>(1, g.pages.size()));
  std::string s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(w) + "mm\" height=\"" + num(h) +
       "mm\" viewBox=\"0 0 " + num(w) + " " + num(h) + "\" role=\"img\" aria-label=\"" + xml_escaped(g.title) +
       "\" lang=\"" + xml_escaped(g.language) + "\">\n";
  s += "<title>" + xml_escaped(g.title) + "</title>\n";
  s += "<style>path,rect{fill:none;stroke:#000;stroke-width:" + num(kTactileLineWidthMm) +
       ";stroke-linecap:round;stroke-linejoin:round} circle{fill:#000} text.braille{font-family:'DejaVu Sans';"
       "font-size:8px} text.print{font-family:'DejaVu Sans';font-size:" +
       num(kPrintTextMm) + "px}</style>\n";
  for (std::size_t p = 0; p < g.pages.size(); ++p) {
    const TactilePage& page = g.pages[p];
    s += "<g id=\"page-" + std::to_string(p + 1) + "\" transform=\"translate(0 " +
         num(g.paper.height_mm * static_cast<double>(p)) + ")\">\n";
    if (page.frame_mm) {
      const auto& f = *page.frame_mm;
      s += "<rect id=\"frame\" x=\"" + num(f[0].x) + "\" y=\"" + num(f[0].y) + "\" width=\"" + num(f[1].x - f[0].x) +
           "\" height=\"" + num(f[1].y - f[0].y) + "\"/>\n";
    }
    for (std::size_t i = 0; i < page.shapes.size(); ++i) {
      s += "<g id=\"shape-" + std::to_string(page.shapes[i].number) + "\" role=\"img\" aria-label=\"" +
           xml_escaped(page.shapes[i].name) + "\">";
      for (const TactileStroke& st : page.strokes)
        if (st.shape == static_cast<int>(i)) s += path_of(st);
      for (const TactileLabel& l : page.labels)
        if (l.shape == static_cast<int>(i)) s += label_svg(l);
      s += "</g>\n";
    }
    for (const TactileStroke& st : page.strokes)
      if (st.shape < 0) s += path_of(st) + "\n";
    for (const TactileLabel& l : page.labels)
      if (l.shape < 0) s += label_svg(l) + "\n";
    if (!page.fill_dots_mm.empty()) {
      s += "<g class=\"fill\" aria-hidden=\"true\">";
      for (const Vec2& d : page.fill_dots_mm)
        s += "<circle cx=\"" + num(d.x) + "\" cy=\"" + num(d.y) + "\" r=\"" + num(kBrailleDotDiameterMm / 2) + "\"/>";
      s += "</g>\n";
    }
    s += "</g>\n";
  }
  s += "</svg>\n";
  return s;
}

std::string tactile_brf(const TactileGraphic& g, BrailleGrade grade) {
  std::vector<std::string> lines;
  if (!g.title.empty()) add_brf_lines(lines, g.title, g.language, grade);
  lines.emplace_back();
  // Each shape's label, as it stands on the picture (a key letter, then the name it stands for).
  if (!g.pages.empty())
    for (const TactileShape& ts : g.pages[0].shapes)
      add_brf_lines(lines, ts.key.empty() ? ts.name : ts.key + " " + ts.name, g.language, grade);
  // The rest of the key: what is not labelled, what was left out, the styles' names.
  const std::size_t keyed =
      g.pages.empty() ? 0
                      : static_cast<std::size_t>(std::count_if(g.pages[0].shapes.begin(), g.pages[0].shapes.end(),
                                                               [](const TactileShape& t) { return !t.key.empty(); }));
  if (g.key_lines.size() > keyed) {
    lines.emplace_back();
    for (std::size_t i = keyed; i < g.key_lines.size(); ++i) add_brf_lines(lines, g.key_lines[i], g.language, grade);
  }
  std::string out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (i > 0 && i % kBrfLinesPerPage == 0) out += '\f';
    out += lines[i] + "\r\n";
  }
  return out;
}

std::string tactile_format_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".pdf" || ext == ".svg" || ext == ".brf") return ext.substr(1);
  return {};
}

void write_tactile(const TactileGraphic& g, const std::string& path, BrailleGrade grade) {
  const std::string format = tactile_format_of(path);
  if (format.empty()) throw CopyError("copy " + hk::quoted(path) + ": the file name must end in .pdf, .svg or .brf");
  const std::filesystem::path final_path(path);
  const std::filesystem::path folder = final_path.parent_path().empty() ? "." : final_path.parent_path();
  std::error_code fec;
  if (!std::filesystem::is_directory(folder, fec))
    throw CopyError("copy " + hk::quoted(path) + ": the folder " + hk::quoted(folder.string()) + " does not exist");
  if (::access(folder.c_str(), W_OK) != 0)
    throw CopyError("copy " + hk::quoted(path) + ": the folder " + hk::quoted(folder.string()) + " cannot be written");
  const std::filesystem::path tmp =
      final_path.parent_path() / ("." + final_path.filename().string() + "." + std::to_string(::getpid()) + ".tmp");
  try {
    if (format == "pdf") {
      write_tactile_pdf(g, tmp.string());
    } else {
      const std::string text = format == "svg" ? tactile_svg(g) : tactile_brf(g, grade);
      std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
      f << text;
      f.close();
      if (!f) throw CopyError("copy " + hk::quoted(path) + ": cannot write the file");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, final_path, ec);
    if (ec) throw CopyError("copy " + hk::quoted(path) + ": " + ec.message());
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

}  // namespace hk::app
