#pragma once
/// @file picture_names.hpp
/// Staff names put on a built scene: the annotation file of its picture (formats/annotations.hpp) read, its
/// regions drawn on the picture and the shapes named (meaning/names.hpp). Applied after a scene is built or
/// taken from the scene cache: names change while the picture does not. Off the window thread (librsvg).

#include <string>

#include "config/settings.hpp"
#include "pictures/image_scene.hpp"

namespace hk::app {

/// The writable names folder of [kiosk] names_dir: "off" → "" (none); "auto" → $STATE_DIRECTORY/names (the
/// service's), else $XDG_DATA_HOME/haptic-kiosk/names, else $HOME/.local/share/haptic-kiosk/names ("" when none of
/// these is an absolute path); else the folder given.
std::string names_dir(const config::Settings& s);

/// The annotation file that names `picture_path`'s shapes: the one in `names_folder` when it exists (names saved at
/// the kiosk win), else the one beside the picture when it exists, else "".
std::string names_file_for(const std::string& picture_path, const std::string& names_folder);

/// The sidecar in the names folder `names_folder` for `picture_path` (NAME.toml there): where the operator panel's
/// Names tab keeps its switch of the kiosk's guesses (`guesses = false`), since the picture's own folder is
/// read-only under the service. "" when there is no names folder.
std::string guesses_sidecar_in(const std::string& names_folder, const std::string& picture_path);

/// Whether the kiosk's own guesses name parts of `picture_path`: the names folder's sidecar (guesses_sidecar_in)
/// when it exists, else `sidecar_guesses` (the sidecar beside the picture, PictureNotes::guesses). A names-folder
/// sidecar that cannot be used is one log line and passed over.
bool guesses_for(const std::string& picture_path, const std::string& names_folder, bool sidecar_guesses);

/// Puts the names of `names_file` (annotations_path's form; "" = none) on `is`: ImageScene::regions and
/// shape_region; then, with `guesses` (a sidecar's `guesses = false` turns them off), the kiosk's own
/// (add_guessed_regions). A file refused whole, and each annotation left out, is one warning in the log naming
/// the file and the rule; the scene keeps the names that were valid (none when the file is refused). Never
/// throws but std::bad_alloc.
void apply_names(ImageScene& is, const std::string& names_file, const std::string& picture_file_name,
                 bool guesses = true);

/// Adds the kiosk's own guesses to `is.regions` and names the shapes again (shape_region): each face of
/// is.faces_m (meaning::kFaceName) and each text block of a picture (its first meaning::kTextNameWords words OCR
/// was sure of, after "text: "; not on a document page, whose text is read as text) as a region of the picture,
/// unless half of it lies in a region staff named. Cheap (a few small masks): the
/// window thread may call it for a capture or a stick's page, which have no names file. Never throws but
/// std::bad_alloc.
void add_guessed_regions(ImageScene& is);

}  // namespace hk::app
