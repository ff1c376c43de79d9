#pragma once
/// @file names_editor.hpp
/// The operator panel's Names tab without its drawing: staff name the shapes of the library picture on show. The
/// editor holds the picture's annotation file (formats/annotations.hpp: the one in the names folder, else the one
/// beside the picture) as an AnnotationSet, one entry per annotation with the curves it names (meaning/names.hpp:
/// the smallest region holding half a curve's points names it). A shape is picked by curve index (the one at the
/// handle: pick_at_hand, or nearest a point on the screen: pick_near), then named; a shape no region names gets a
/// new annotation whose target is an SvgSelector drawing its outline (a filled polygon for a closed curve, a
/// stroked polyline for an open one) in the file's coordinates (the canvas's when the file has one, else the
/// picture's full-detail pixels), with motivation `identifying` and the description as a `describing` body.
/// Renaming edits the annotation's body (every curve its region names takes the new name); deleting removes the
/// annotation. Nothing is on disk until save(): NAME.annotations.json written into the names folder (created when
/// missing) with config::write_file_atomic (a temporary file in the same folder, fsync, rename, the old file kept
/// as `.bak`), every annotation the file had kept and written again, then read back with apply_names so the
/// regions handed to the stage (Stage::set_names) are exactly what the kiosk will read at its next start.
///
/// Bad input is refused with one line and nothing changes: an empty name, one over kMaxNameBytes (200 bytes) or
/// with a control character, a description over kMaxRegionDescriptionBytes. A folder that cannot be written
/// leaves the old file as it was, and status() says so in one line ("Could not save names to /path: Permission
/// denied"). Window thread only (librsvg draws the regions: milliseconds a region); nothing here reaches the servo
/// thread.

#include <cstddef>
#include <string>
#include <vector>

#include "formats/annotations.hpp"
#include "hk/vec2.hpp"
#include "meaning/names.hpp"
#include "meaning/shape_descriptors.hpp"
#include "pictures/image_scene.hpp"

namespace hk::app {

/// The picture whose shapes are named: what is shown, copied (the editor outlives a frame).
struct NamesPicture {
  std::string picture_path;                           ///< the library picture's file; "" when none is shown
  cv::Mat picture;                                    ///< BGR pixels `px_to_m` maps (shared, not copied)
  int file_width_px = 0, file_height_px = 0;          ///< its full-detail size [px]; 0: picture's
  vision::PxToM px_to_m{1, 0, 0};                     ///< picture pixels → workspace metres
  std::vector<Polyline> polylines;                    ///< the curves shown [m]
  std::vector<meaning::ShapeDescriptor> descriptors;  ///< one per polyline, or empty (no specks known)
  std::vector<Aabb> faces_m;                          ///< faces guessed [m] (ImageScene::faces_m)
  std::vector<TextBlockM> text_blocks;                ///< its text blocks [m]
  bool guesses = true;  ///< the kiosk's guesses name its parts (picture_names.hpp guesses_for)
};

/// One annotation of the file: a name and the curves it gives it to.
struct NamesEntry {
  std::string name;         ///< as staff wrote it ("left wing"); may be empty when only described
  std::string description;  ///< may be empty
  std::vector<int> curves;  ///< indices of the curves that take their name from it (none: its region holds none)
};

/// What the last save did.
enum class NamesSaved {
  none,    ///< nothing saved since the picture was opened
  saved,   ///< written and read back
  failed,  ///< refused or not written; the old file untouched
};

/// The Names tab's state and actions for one picture at a time. Not thread-safe: the window thread.
class NamesEditor {
 public:
  /// Most outline points written for a new shape's SvgSelector (longer curves are thinned evenly), so its SVG
  /// stays far below kMaxSvgBytes.
  static constexpr std::size_t kMaxOutlinePoints = 2000;

  /// `names_folder`: the writable names folder (names_dir of the settings); "" when there is none (saving is then
  /// refused with a line saying so).
  explicit NamesEditor(std::string names_folder) : folder_(std::move(names_folder)) {}

  /// Opens the names of `picture` (the picture on show): the annotation file names_file_for finds read (a file
  /// refused whole, or annotations left out, said in status(): they are not written back), the regions drawn,
  /// the entries listed; the selection and the edit boxes cleared. A picture without a file path (a practice
  /// shape, a stick's page, a capture) opens with nothing to name (is_open() false).
  void open(NamesPicture picture);
  /// The names folder saves go to ("" none).
  const std::string& folder() const { return folder_; }
  /// Whether a library picture is open.
  bool is_open() const { return !picture_.picture_path.empty() && !picture_.picture.empty(); }
  /// The picture open ("" none).
  const std::string& picture_path() const { return picture_.picture_path; }

  /// The file's annotations, in file order, each with the curves it names.
  const std::vector<NamesEntry>& entries() const { return entries_; }
  /// The annotation selected (index into entries()), −1 for none (a picked shape no region names yet).
  int selected() const { return selected_; }
  /// The curve picked, −1 for none.
  int picked_curve() const { return picked_; }

  /// Picks curve `curve` (an index into the picture's polylines; out of range: nothing picked): its annotation is
  /// selected (−1 when no region names it) and the edit boxes hold its name and description (empty for none).
  void pick(int curve);
  /// Picks the shape at the handle (describe.hpp shape_at_hand: the curve the proxy rests on, `contact_curve`,
  /// else the one nearest `hand_m` [m], specks left out). Returns the curve picked, −1 when there are none.
  int pick_at_hand(Vec2 hand_m, int contact_curve);
  /// Picks the curve nearest the point `p_m` [m] (a click on the picture mapped to the workspace) when it lies
  /// within `within_m` [m]; else nothing changes. Returns the curve picked, −1 for none.
  int pick_near(Vec2 p_m, double within_m);
  /// Selects entry `index` (a click in the list; out of range: nothing) and the first curve it names.
  void select_entry(int index);

  /// The name edit box's text (what the operator typed; refused or not).
  std::string& name_text() { return name_text_; }
  /// The description edit box's text.
  std::string& description_text() { return description_text_; }

  /// Gives `name` and `description` to the selection: the selected annotation's body is edited (a rename), else
  /// the picked curve gets a new annotation drawing its outline. In memory only (save() writes it). Returns ""
  /// when done, else the one-line reason nothing changed ("A name is needed.", "The name is 201 bytes; at most
  /// 200.", "Pick a shape first.").
  std::string set_name(const std::string& name, const std::string& description);
  /// Removes the selected annotation (in memory). Returns "" when done, else why not ("Nothing is selected.").
  std::string remove_selected();
  /// Whether the annotations differ from the file last read or written.
  bool dirty() const { return dirty_; }

  /// Writes the annotations to `<names folder>/NAME.annotations.json` (write_annotation_page; the folder
  /// created when missing) atomically, keeping the old file as `.bak`, then reads it back with apply_names.
  /// True when written; else false, the old file untouched, and status() says why in one line ("Could not save
  /// names to /srv/names/horse.annotations.json: Permission denied").
  bool save();
  /// The panel's "Save names": the edit boxes given to the selection (set_name) when a shape is picked, a name
  /// selected or a box holds text, then save(). False, with last_save() failed and status() the reason, when the name
  /// is refused (nothing is written then) or the file is not written.
  bool save_typed();
  /// The panel's "Delete name": remove_selected(), then save(). False as save_typed.
  bool delete_and_save();
  /// The last save's outcome (for the panel's status line).
  NamesSaved last_save() const { return last_save_; }
  /// The file save() writes ("" when there is no names folder or no picture).
  std::string target_file() const;
  /// One line: what the last action did, or why it did not.
  const std::string& status() const { return status_; }

  /// Whether the kiosk's own guesses (faces, text blocks) name parts of the picture open.
  bool guesses() const { return picture_.guesses; }
  /// Turns the kiosk's guesses on this picture on or off: the names folder's sidecar for it (guesses_sidecar_in:
  /// `guesses = true|false`) written with config::write_file_atomic, then the names read again (regions()).
  /// True when written; else false, nothing changed, and status() says why in one line.
  bool set_guesses(bool on);

  /// The names as the kiosk reads them now (after open, or save's read-back): regions on the picture's pixels and
  /// one region index per curve (−1 none), for Stage::set_names.
  const std::vector<meaning::NamedRegion>& regions() const { return scene_.regions; }
  const std::vector<int>& shape_region() const { return scene_.shape_region; }

 private:
  void refresh();  // the regions and entries drawn again from set_
  std::string outline_svg(int curve) const;
  void load_texts();

  std::string folder_;
  NamesPicture picture_;
  ImageScene scene_;  // picture, polylines and px_to_m of picture_; regions and shape_region as read back
  AnnotationSet set_;
  std::vector<meaning::NamedRegion> drawn_;  // regions of set_ (with unsaved edits)
  std::vector<int> drawn_shape_region_;      // per curve: an index into drawn_, −1 none
  std::vector<NamesEntry> entries_;
  int selected_ = -1, picked_ = -1;
  std::string name_text_, description_text_, status_;
  bool dirty_ = false;
  NamesSaved last_save_ = NamesSaved::none;
};

}  // namespace hk::app
