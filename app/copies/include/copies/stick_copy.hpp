#pragma once
/// @file stick_copy.hpp
/// A take-home copy written onto the visitor's USB stick: a new folder at the stick's top, named for the picture
/// in the visitor's language ("Butterfly (tactile copy)"), holding the copy as PDF (swell paper, embossers), SVG
/// (pin displays, screens) and BRF (text embossers), each named for the picture. Never over anything: a folder of
/// that name already there gives "… (tactile copy) 2", then 3, …; every file is created new (O_EXCL). A write that
/// fails (a full stick, a stick taken out) removes whatever it wrote, so the stick is left as it was.

#include <string>
#include <vector>

#include "copies/tactile_output.hpp"

namespace hk::app {

/// The stick has no room for the copy (ENOSPC, EDQUOT, EFBIG). Nothing of the copy is left on it.
class CopyNoRoomError : public CopyError {
 public:
  using CopyError::CopyError;
};

/// What was written: the folder's name (in the stick's top folder) and its files' names, in order.
struct SavedCopy {
  std::string folder;
  std::vector<std::string> files;
};

/// The longest folder or file name written [bytes] (FAT and exFAT allow 255 UTF-16 units; this leaves room for
/// the " 99" and the extension).
inline constexpr std::size_t kCopyNameMaxBytes = 120;
/// The most folders of one name tried (" 2" to " 99") before giving up.
inline constexpr int kCopyFolderTries = 99;

/// `text` as a name FAT and exFAT accept: the characters they refuse (" * / : < > ? \ |, control characters)
/// become '-', spaces and dots at either end are dropped, and it is cut at a UTF-8 character's boundary to
/// kCopyNameMaxBytes; `fallback` when nothing is left.
std::string stick_safe_name(const std::string& text, const std::string& fallback);

/// Writes `g` (PDF, SVG, BRF at `grade`) into a new folder of the folder `top` (the stick's top folder, writable):
/// the folder named `folder_pattern` with "{title}" replaced by the title (stick_safe_name), the files named for
/// the title with .pdf, .svg and .brf.
/// @throws CopyNoRoomError when the stick is full; CopyError (one line naming the folder) for any other failure:
/// `top` missing or not writable, kCopyFolderTries folders of the name already there, a write that fails. Either
/// way nothing of the copy is left in `top`.
SavedCopy save_copy_folder(const TactileGraphic& g, const std::string& top, const std::string& folder_pattern,
                           BrailleGrade grade);

}  // namespace hk::app
