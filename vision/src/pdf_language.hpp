#pragma once
/// @file pdf_language.hpp
/// A PDF's language as its catalog says it (/Lang, PDF 32000-1 §14.9.2), read with qpdf since poppler-cpp does not
/// expose it. Its own file because qpdf 11's headers compile as C++17 with clang, not as C++20 (the fuzz harness
/// of pdf.cpp builds this file with -std=c++17).

#include <cstddef>
#include <cstdint>
#include <string>

namespace hk::vision {

/// The catalog's /Lang of the PDF in `data` (`size` bytes) as written (UTF-8); "" when it has none, it is not a
/// string, or qpdf cannot read the file. Never throws.
std::string pdf_catalog_language(const std::uint8_t* data, std::size_t size);

}  // namespace hk::vision
