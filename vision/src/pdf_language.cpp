// A PDF's /Lang with qpdf (pdf_language.hpp).
#include "pdf_language.hpp"

// qpdf 11: the std::shared_ptr API only, without its transition warning.
#define POINTERHOLDER_TRANSITION 4
#include <qpdf/QPDF.hh>
#include <qpdf/QPDFObjectHandle.hh>

namespace hk::vision {

std::string pdf_catalog_language(const std::uint8_t* data, std::size_t size) {
  try {
    QPDF q;
    q.setSuppressWarnings(true);
    q.processMemoryFile("document", reinterpret_cast<const char*>(data), size);
    QPDFObjectHandle lang = q.getRoot().getKey("/Lang");
    return lang.isString() ? lang.getUTF8Value() : std::string();
  } catch (...) {  // a damaged catalog: no language; poppler still reads the pages
    return {};
  }
}

}  // namespace hk::vision
