#include "pictures/documents.hpp"

#include "formats/picture_notes.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "pictures/picture_params.hpp"
#include "vision/intake.hpp"

namespace hk::app {

bool is_pdf_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return false;
  struct stat st {};
  bool regular = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  std::vector<std::uint8_t> head(1024 + 8);
  const ssize_t n = regular ? ::read(fd, head.data(), head.size()) : 0;
  ::close(fd);
  if (n <= 0) return false;
  head.resize(static_cast<std::size_t>(n));
  return vision::looks_like_pdf(head);
}

int StickListing::pictures() const {
  int n = 0;
  for (const ListedDocument& d : documents) n += d.doc.kind == vision::DocumentKind::Image;
  return n;
}

int StickListing::pdfs() const { return static_cast<int>(documents.size()) - pictures(); }

std::string pdf_title(const std::string& raw) {
  std::string t = usable_note(raw, kMaxTitleBytes, false);
  static const char* const kOfficePrefixes[] = {"Microsoft Word - ", "Microsoft PowerPoint - ", "Microsoft Excel - "};
  for (const char* p : kOfficePrefixes)
    if (t.rfind(p, 0) == 0) return "";
  std::string lower = t;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower == "untitled" || lower == "untitled document" || lower == "title") return "";
  return t;
}

StickListing list_stick(const std::string& root, const config::Settings& s) {
  StickListing out;
  out.scan = vision::scan_stick(root, scan_limits_from(s));
  out.refused = std::move(out.scan.refused);
  const vision::PdfLimits pl = pdf_limits_from(s);
  const auto t0 = std::chrono::steady_clock::now();
  for (vision::StickDocument& d : out.scan.documents) {
    ListedDocument ld;
    if (d.kind == vision::DocumentKind::Pdf) {
      try {
        const std::vector<std::uint8_t> bytes = vision::read_stick_file(root, d.path, s.stick.max_file_bytes);
        const vision::PdfInfo info = vision::probe_pdf(bytes, d.display_name, pl);
        ld.pages = info.pages;
        ld.pages_in_file = info.pages_in_file;
        ld.title = pdf_title(info.title);
      } catch (const std::exception& e) {  // PdfError, StickError: this document only
        out.refused.push_back({d.display_name, e.what(), true});
        continue;
      }
    }
    ld.doc = std::move(d);
    out.documents.push_back(std::move(ld));
  }
  out.scan.documents.clear();
  out.probe_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

nlohmann::json stick_listing_json(const StickListing& l) {
  nlohmann::json docs = nlohmann::json::array();
  for (const ListedDocument& d : l.documents) {
    nlohmann::json j{{"path", d.doc.display_name},
                     {"kind", d.doc.kind == vision::DocumentKind::Pdf ? "pdf" : "image"},
                     {"format", d.doc.format},
                     {"bytes", d.doc.bytes},
                     {"pages", d.pages}};
    if (d.pages_in_file != d.pages) j["pages_in_file"] = d.pages_in_file;
    if (!d.title.empty()) j["title"] = d.title;
    docs.push_back(std::move(j));
  }
  nlohmann::json refused = nlohmann::json::array();
  for (const vision::RefusedEntry& r : l.refused) refused.push_back({{"path", r.path}, {"reason", r.reason}});
  return {{"documents", std::move(docs)},       {"refused", std::move(refused)},
          {"complete", l.scan.complete},        {"entries_scanned", l.scan.entries_scanned},
          {"scan_ms", 1000.0 * l.scan.seconds}, {"probe_ms", l.probe_ms}};
}

ImageScene build_pdf_page_scene(const std::vector<std::uint8_t>& bytes, const std::string& name, int page,
                                const config::Settings& s, vision::PdfFault fault, TextTiming timing,
                                int text_layer_side_px) {
  vision::PdfLimits limits = pdf_limits_from(s);
  limits.fault = fault;
  limits.text_layer_max_side_px = std::max(text_layer_side_px, 0);
  double render_ms = 0;
  const auto draw = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    vision::PdfPage drawn = vision::render_pdf_page(bytes, name, page, limits);
    render_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return drawn;
  };
  vision::PdfPage pg = draw();
  PageTextChoice text;
  text.read = wants_page_text(pg, s, text.why);
  if (pg.screen_sized && text.read) {  // the layer leaves text out: OCR reads the page drawn at the full budget
    limits.text_layer_max_side_px = 0;
    pg = draw();
    text.read = wants_page_text(pg, s, text.why);
  }
  ImageScene is = build_page_scene(pg, name, page, s, timing, &text);
  is.times.load_ms += render_ms;
  is.render_dpi = pg.dpi;
  is.worker_ms = pg.worker_ms;
  is.worker_max_rss_kb = pg.worker_max_rss_kb;
  is.document_title = pdf_title(pg.title);
  is.document_language = pg.language;
  return is;
}

}  // namespace hk::app
