#pragma once
/// @file documents.hpp
/// Documents (pictures and PDF pages) as the app sees them: the settings turned into the vision
/// module's limits, a document's bytes read with a size limit, one page of it built into a scene, and the
/// listing of a stick that the `stick` command prints and the kiosk speaks.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/settings.hpp"
#include "pictures/image_scene.hpp"
#include "vision/pdf.hpp"
#include "vision/stick_scan.hpp"

namespace hk::app {

/// Whether the file at `path` starts with "%PDF-" (reads its first kilobyte; false when unreadable).
bool is_pdf_file(const std::string& path);

/// One document of a stick, with its page count (1 for a picture).
struct ListedDocument {
  vision::StickDocument doc;
  int pages = 1;          ///< pages offered (a PDF's are capped at [stick] max_pdf_pages)
  int pages_in_file = 1;  ///< pages the document has
  std::string title;  ///< a PDF's title (pdf_title of its Info /Title), spoken in place of its file name; "" when none
};

/// The title of a PDF to speak, from vision::PdfInfo::title as the file gives it: usable_note (one line, at
/// most kMaxTitleBytes, valid UTF-8, not blank, no placeholder) and not what an office program writes in
/// place of one ("Microsoft Word - report.docx", "untitled"); "" when none is usable.
std::string pdf_title(const std::string& raw);

/// What a stick offers: the scan, with every PDF probed in the worker (its pages counted). A PDF the
/// worker refuses (locked, damaged, hostile) moves from the documents to `refused`, with its reason.
struct StickListing {
  std::vector<ListedDocument> documents;
  std::vector<vision::RefusedEntry> refused;
  vision::StickScan scan;  ///< the walk's own figures (entries, complete, seconds); its lists are moved out
  double probe_ms = 0.0;   ///< time spent counting PDF pages [ms]
  int pictures() const;    ///< documents that are pictures
  int pdfs() const;        ///< documents that are PDFs
};

/// Scans the folder `root` (a mounted stick, or any folder) and probes its PDFs, with the [stick] limits.
/// @throws vision::StickError when root is not a readable folder.
StickListing list_stick(const std::string& root, const config::Settings& s);

/// The `stick` command's JSON: {"documents": [{"path", "kind": "image"|"pdf", "pages"}], "refused":
/// [{"path", "reason"}], "complete", "entries_scanned", "scan_ms"} (paths relative to the root, made safe).
nlohmann::json stick_listing_json(const StickListing& listing);

/// Builds the scene of page `page` (from 1) of the PDF held in `bytes`, named `name`: drawn in the worker
/// (vision::render_pdf_page with the [stick] limits), then build_page_scene (text masked, kept as blocks).
/// The drawing time is added to times.load_ms. `timing` as build_page_scene's.
/// `text_layer_side_px` > 0: a page with a text layer is drawn with its long side at most this [px] (the
/// screen's picture side; vision::PdfLimits::text_layer_max_side_px), which takes a fraction of the full
/// budget's drawing. When that page's layer leaves its text out (wants_page_text), it is drawn again at the
/// full budget, for OCR. 0: every page at the full budget (explore, whose outputs keep the page's detail).
/// @throws vision::PdfError (one line: not a PDF, locked, damaged, no such page, worker stopped).
/// `fault` is the worker's test hook (vision::PdfFault): None outside tests.
ImageScene build_pdf_page_scene(const std::vector<std::uint8_t>& bytes, const std::string& name, int page,
                                const config::Settings& s, vision::PdfFault fault = vision::PdfFault::None,
                                TextTiming timing = TextTiming::now, int text_layer_side_px = 0);

}  // namespace hk::app
