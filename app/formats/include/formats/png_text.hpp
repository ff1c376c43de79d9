#pragma once
/// @file png_text.hpp
/// A PNG's own words about itself: the `Title` and `Description` of its text chunks
/// (tEXt, zTXt, iTXt; W3C PNG 2nd ed. §11.3.4), read chunk by chunk without decoding the image data (zlib
/// checks each text chunk's CRC and inflates compressed text). exiv2, which reads the pictures' other
/// metadata (picture_notes.cpp), ignores a PNG's Title.

#include <string>

namespace hk::app {

/// The text chunks' values of the keywords "Title" and "Description", as UTF-8 (tEXt and zTXt are Latin-1 and
/// converted; iTXt is UTF-8 already), unchecked: the caller checks them (usable_note). The first chunk with a
/// keyword wins, wherever it is in the file (before or after the image data). A text chunk larger than 1 MiB,
/// stored or inflated, is skipped (a zTXt bomb is not expanded past it), as is one whose CRC does not match or
/// that is malformed. Empty strings for a file that is not a PNG or has no such chunk; a truncated file gives
/// what came before the cut (never throws; nothing is printed).
struct PngText {
  std::string title;
  std::string description;
};
PngText read_png_text(const std::string& path);

}  // namespace hk::app
