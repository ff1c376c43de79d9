/// @file test_names_editor.cpp
/// The operator panel's Names tab without a window (visit/names_editor.hpp), on a drawn picture whose three curves
/// are known: a round shape on the left, a square on the right and an open line at the bottom. A shape picked at
/// the handle and named is saved into the names folder as a W3C AnnotationPage that read_annotations reads back
/// to the same name, and apply_names + name_shapes give the picked curve (and only it) that name; a file beside
/// the picture is kept and written again with the new name; rename and delete; refusals that change nothing (an
/// empty name, one of 201 bytes, a folder that cannot be written: the old file stays byte for byte).

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "config/load.hpp"
#include "formats/annotations.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_names.hpp"
#include "visit/names_editor.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// A folder of its own under the temporary folder, removed at the end (made writable first).
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    for (const auto& e : fs::recursive_directory_iterator(path, ec))
      if (e.is_directory(ec)) fs::permissions(e.path(), fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path, ec);
  }
};

constexpr int kW = 400, kH = 300;  // the picture shown [px]

/// Picture pixel (u, v) → workspace metres under `m`.
Vec2 at(const vision::PxToM& m, double u, double v) { return {m.x_m(u), m.y_m(v)}; }

/// A 400 x 300 picture (its file 800 x 600: shown at half size) with three curves in metres: 0 a circle of radius 40
/// px about (100, 120), 1 a square 120..200 x 260..340 (v, u), 2 an open line along v = 260 from u = 60 to 340.
/// The picture file `dir`/`file` is written (white).
NamesPicture picture_in(const fs::path& dir, const std::string& file = "birds.png") {
  NamesPicture p;
  p.picture_path = (dir / file).string();
  p.picture = cv::Mat(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::imwrite(p.picture_path, cv::Mat(2 * kH, 2 * kW, CV_8UC3, cv::Scalar(255, 255, 255)));
  p.file_width_px = 2 * kW;
  p.file_height_px = 2 * kH;
  p.px_to_m = vision::fit_to_workspace(kW, kH, 0.14, 0.09);
  Polyline circle{{}, true}, square{{}, true}, line{{}, false};
  for (int k = 0; k < 120; ++k) {
    const double a = 2 * std::numbers::pi * k / 120;
    circle.points_m.push_back(at(p.px_to_m, 100 + 40 * std::cos(a), 120 + 40 * std::sin(a)));
  }
  for (int k = 0; k < 80; ++k) {  // 20 points a side, clockwise from the top left corner
    const double t = (k % 20) / 20.0 * 80;
    const int side = k / 20;
    const double u = side == 0 ? 260 + t : side == 1 ? 340 : side == 2 ? 340 - t : 260;
    const double v = side == 0 ? 120 : side == 1 ? 120 + t : side == 2 ? 200 : 200 - t;
    square.points_m.push_back(at(p.px_to_m, u, v));
  }
  for (int k = 0; k <= 70; ++k) line.points_m.push_back(at(p.px_to_m, 60 + 4 * k, 260));
  p.polylines = {circle, square, line};
  return p;
}

/// The names the kiosk reads for `p` from `folder` (names_file_for, apply_names), one per curve ("" none).
std::vector<std::string> names_read(const NamesPicture& p, const std::string& folder) {
  ImageScene is;
  is.picture = p.picture;
  is.polylines = p.polylines;
  is.px_to_m = p.px_to_m;
  is.file_width_px = p.file_width_px;
  is.file_height_px = p.file_height_px;
  apply_names(is, names_file_for(p.picture_path, folder), fs::path(p.picture_path).filename().string());
  std::vector<std::string> out;
  for (int r : is.shape_region) out.push_back(r < 0 ? "" : is.regions[static_cast<std::size_t>(r)].name);
  return out;
}

TEST(NamesEditor, AShapePickedAtTheHandleNamedAndSavedReadsBackWithItsNameOnThatCurveOnly) {
  TempDir dir("hk_names_pick");
  const NamesPicture p = picture_in(dir.path);
  const fs::path folder = dir.path / "names" / "saved";  // missing: save creates it
  NamesEditor ed(folder.string());
  ed.open(p);
  ASSERT_TRUE(ed.is_open());
  EXPECT_TRUE(ed.entries().empty());
  // The hand 1 mm outside the square's right side, touching nothing: the nearest shape is picked.
  const Vec2 hand = at(p.px_to_m, 340, 160) + Vec2{0.001, 0};
  EXPECT_EQ(ed.pick_at_hand(hand, -1), 1);
  EXPECT_EQ(ed.selected(), -1) << "no region names it yet";
  ed.name_text() = "left wing";
  ed.description_text() = "the wing nearer the window";
  ASSERT_TRUE(ed.save_typed()) << ed.status();
  EXPECT_EQ(ed.last_save(), NamesSaved::saved);

  const fs::path file = folder / "birds.annotations.json";
  ASSERT_EQ(ed.target_file(), file.string());
  const AnnotationSet set = read_annotations(file.string(), "birds.png");
  ASSERT_EQ(set.annotations.size(), 1u);
  EXPECT_TRUE(set.problems.empty());
  EXPECT_EQ(set.annotations[0].name, "left wing");
  EXPECT_EQ(set.annotations[0].description, "the wing nearer the window");
  EXPECT_EQ(set.annotations[0].selector.kind, AnnotationSelector::Kind::svg);
  const std::string text = read_file(file);
  for (const char* part : {"\"AnnotationPage\"", "\"identifying\"", "\"describing\"", "\"SvgSelector\"", "<polygon"})
    EXPECT_NE(text.find(part), std::string::npos) << part << " in " << text;

  EXPECT_EQ(names_read(p, folder.string()), (std::vector<std::string>{"", "left wing", ""}));
  // What the editor hands the stage is what the kiosk reads.
  ASSERT_EQ(ed.shape_region().size(), 3u);
  ASSERT_GE(ed.shape_region()[1], 0);
  EXPECT_EQ(ed.regions()[static_cast<std::size_t>(ed.shape_region()[1])].name, "left wing");
  EXPECT_EQ(ed.shape_region()[0], -1);
  EXPECT_EQ(ed.shape_region()[2], -1);
  ASSERT_EQ(ed.entries().size(), 1u);
  EXPECT_EQ(ed.entries()[0].curves, std::vector<int>{1});
}

TEST(NamesEditor, AnOpenLineAndAShapeNearAClickAreNamedByTheirOwnOutlines) {
  TempDir dir("hk_names_line");
  const NamesPicture p = picture_in(dir.path);
  NamesEditor ed((dir.path / "names").string());
  ed.open(p);
  EXPECT_EQ(ed.pick_near(at(p.px_to_m, 200, 262), 0.002), 2) << "2 px from the line";
  ASSERT_EQ(ed.set_name("horizon", ""), "");
  EXPECT_EQ(ed.pick_near(at(p.px_to_m, 100, 20), 0.002), -1) << "60 px from everything: nothing picked";
  EXPECT_EQ(ed.picked_curve(), 2);
  EXPECT_EQ(ed.pick_near(at(p.px_to_m, 141, 120), 0.002), 0);
  ASSERT_EQ(ed.set_name("Sun", ""), "");
  ASSERT_TRUE(ed.save()) << ed.status();
  EXPECT_EQ(names_read(p, (dir.path / "names").string()), (std::vector<std::string>{"Sun", "", "horizon"}));
}

TEST(NamesEditor, TheFileBesideThePictureIsKeptRenamedAndDeletedInTheNamesFolder) {
  TempDir dir("hk_names_edit");
  const NamesPicture p = picture_in(dir.path);
  // Staff's own file beside the picture: a box (full-detail pixels, the file is 800 x 600) round the circle.
  const fs::path beside = dir.path / "birds.annotations.json";
  AnnotationSet staff;
  Annotation sun;
  sun.name = "sun";
  sun.selector.x = 2 * 50;
  sun.selector.y = 2 * 70;
  sun.selector.w = 2 * 100;
  sun.selector.h = 2 * 100;
  staff.annotations.push_back(sun);
  std::ofstream(beside) << write_annotation_page(staff, "birds.png");
  const std::string beside_bytes = read_file(beside);
  const fs::path folder = dir.path / "names";

  NamesEditor ed(folder.string());
  ed.open(p);
  ASSERT_EQ(ed.entries().size(), 1u);
  EXPECT_EQ(ed.entries()[0].name, "sun");
  EXPECT_EQ(ed.entries()[0].curves, std::vector<int>{0});
  ed.pick(1);
  ASSERT_EQ(ed.set_name("house", "with a red door"), "");
  ASSERT_TRUE(ed.save()) << ed.status();
  EXPECT_EQ(names_read(p, folder.string()), (std::vector<std::string>{"sun", "house", ""}));
  EXPECT_EQ(read_file(beside), beside_bytes) << "staff's own file is never written";
  EXPECT_FALSE(fs::exists(folder / "birds.annotations.json.bak")) << "there was no file to keep";

  // Rename: picking the circle selects the box that names it; its body changes, its region does not.
  ed.pick(0);
  EXPECT_EQ(ed.selected(), 0);
  EXPECT_EQ(ed.name_text(), "sun");
  ed.name_text() = "moon";
  ASSERT_TRUE(ed.save_typed()) << ed.status();
  EXPECT_EQ(names_read(p, folder.string()), (std::vector<std::string>{"moon", "house", ""}));
  const AnnotationSet saved = read_annotations((folder / "birds.annotations.json").string(), "birds.png");
  ASSERT_EQ(saved.annotations.size(), 2u);
  EXPECT_EQ(saved.annotations[0].selector.kind, AnnotationSelector::Kind::rect);
  EXPECT_DOUBLE_EQ(saved.annotations[0].selector.w, 200);
  EXPECT_EQ(saved.annotations[1].description, "with a red door");
  const AnnotationSet before = read_annotations((folder / "birds.annotations.json.bak").string(), "birds.png");
  ASSERT_EQ(before.annotations.size(), 2u) << "the file replaced is kept as .bak";
  EXPECT_EQ(before.annotations[0].name, "sun");

  // Delete: the house's name goes, the moon's stays; a new editor on the same picture reads the same.
  ed.select_entry(1);
  EXPECT_EQ(ed.picked_curve(), 1);
  ASSERT_TRUE(ed.delete_and_save()) << ed.status();
  EXPECT_EQ(names_read(p, folder.string()), (std::vector<std::string>{"moon", "", ""}));
  NamesEditor again(folder.string());
  again.open(p);
  ASSERT_EQ(again.entries().size(), 1u);
  EXPECT_EQ(again.entries()[0].name, "moon");
  EXPECT_EQ(again.remove_selected(), "Nothing is selected: pick a named shape or click a name in the list.");
}

TEST(NamesEditor, AnEmptyNameAndOneOf201BytesAreRefusedInOneLineAndNothingIsWritten) {
  TempDir dir("hk_names_long");
  const NamesPicture p = picture_in(dir.path);
  NamesEditor ed((dir.path / "names").string());
  ed.open(p);
  ed.pick(1);
  ed.name_text() = std::string(201, 'a');
  EXPECT_FALSE(ed.save_typed());
  EXPECT_EQ(ed.last_save(), NamesSaved::failed);
  EXPECT_EQ(ed.status(), "The name is 201 bytes; at most 200.");
  ed.name_text().clear();
  EXPECT_FALSE(ed.save_typed());
  EXPECT_EQ(ed.status(), "A name is needed (Delete name removes one).");
  EXPECT_EQ(ed.set_name("a\x01name", ""), "The name has a control character.");
  EXPECT_FALSE(fs::exists(dir.path / "names")) << "nothing was written, not even the folder";
  EXPECT_TRUE(ed.entries().empty());
  // 200 bytes is a name.
  ed.name_text() = std::string(200, 'a');
  ASSERT_TRUE(ed.save_typed()) << ed.status();
  EXPECT_EQ(names_read(p, (dir.path / "names").string())[1], std::string(200, 'a'));
  // Nothing picked: a typed name has no shape to go to.
  NamesEditor fresh((dir.path / "names").string());
  fresh.open(p);
  fresh.name_text() = "tree";
  EXPECT_FALSE(fresh.save_typed());
  EXPECT_EQ(fresh.status(), "Pick a shape first.");
}

/// A names folder holding `old` as the picture's file; the editor's save must fail on it.
void expect_save_fails_keeping(NamesEditor& ed, const NamesPicture& p, const fs::path& file, const std::string& old) {
  ed.open(p);
  ed.pick(1);
  ed.name_text() = "roof";
  EXPECT_FALSE(ed.save_typed());
  EXPECT_EQ(ed.last_save(), NamesSaved::failed);
  EXPECT_EQ(ed.status().find('\n'), std::string::npos) << ed.status();
  EXPECT_EQ(read_file(file), old) << "the old file is untouched";
}

TEST(NamesEditor, AReadOnlyNamesFolderKeepsTheOldFileByteForByteAndSaysWhy) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root, which ignores a folder's permissions";
  TempDir dir("hk_names_ro");
  const NamesPicture p = picture_in(dir.path);
  const fs::path folder = dir.path / "names", file = folder / "birds.annotations.json";
  NamesEditor ed(folder.string());
  ed.open(p);
  ed.pick(0);
  ASSERT_EQ(ed.set_name("sun", ""), "");
  ASSERT_TRUE(ed.save()) << ed.status();
  const std::string old = read_file(file);
  ASSERT_EQ(::chmod(folder.c_str(), 0500), 0);
  expect_save_fails_keeping(ed, p, file, old);
  EXPECT_EQ(ed.status(), "Could not save names to " + file.string() + ": Permission denied");
  EXPECT_EQ(std::distance(fs::directory_iterator(folder), fs::directory_iterator()), 1) << "no temporary file left";
}

TEST(NamesEditor, AFolderThatCannotBeWrittenEvenByRootKeepsTheOldFileAndSaysWhy) {
  TempDir dir("hk_names_fail");
  const NamesPicture p = picture_in(dir.path);
  // The names folder is a regular file: nothing can be made in it.
  const fs::path not_a_folder = dir.path / "names";
  std::ofstream(not_a_folder) << "not a folder\n";
  NamesEditor ed(not_a_folder.string());
  expect_save_fails_keeping(ed, p, not_a_folder, "not a folder\n");
  EXPECT_EQ(ed.status().rfind("Could not save names to " + not_a_folder.string() + ": ", 0), 0u) << ed.status();

  // A folder with the old file whose .bak cannot be replaced (a folder of that name, not empty): the save stops
  // before the rename, the old file stays as it was and no temporary file is left.
  const fs::path folder = dir.path / "saved", file = folder / "birds.annotations.json";
  NamesEditor first(folder.string());
  first.open(p);
  first.pick(0);
  ASSERT_EQ(first.set_name("sun", ""), "");
  ASSERT_TRUE(first.save()) << first.status();
  const std::string old = read_file(file);
  fs::create_directories(folder / "birds.annotations.json.bak" / "in the way");
  NamesEditor ed2(folder.string());
  expect_save_fails_keeping(ed2, p, file, old);
  EXPECT_EQ(ed2.status().rfind("Could not save names to " + file.string() + ": ", 0), 0u) << ed2.status();
  EXPECT_EQ(std::distance(fs::directory_iterator(folder), fs::directory_iterator()), 2);
  EXPECT_EQ(names_read(p, folder.string()), (std::vector<std::string>{"sun", "", ""}));
}

TEST(NamesEditor, ACanvasOfItsOwnSizeIsKeptWhenTheFileIsWrittenAgain) {
  TempDir dir("hk_names_canvas");
  const NamesPicture p = picture_in(dir.path);
  // A Manifest-like set whose canvas is 4000 x 3000 (ten times the picture shown): a box round the circle.
  AnnotationSet staff;
  staff.canvas_width_px = 4000;
  staff.canvas_height_px = 3000;
  Annotation sun;
  sun.name = "sun";
  sun.selector = {AnnotationSelector::Kind::rect, 500, 700, 1000, 1000, false, ""};
  staff.annotations.push_back(sun);
  const std::string text = write_annotation_page(staff, "birds.png");
  const AnnotationSet back = parse_annotations(text, "t", "birds.png");
  EXPECT_EQ(back.canvas_width_px, 4000);
  EXPECT_EQ(back.canvas_height_px, 3000);
  std::ofstream(dir.path / "birds.annotations.json") << text;

  NamesEditor ed((dir.path / "names").string());
  ed.open(p);
  ASSERT_EQ(ed.entries().size(), 1u);
  EXPECT_EQ(ed.entries()[0].curves, std::vector<int>{0});
  ed.pick(1);
  ASSERT_EQ(ed.set_name("house", ""), "");
  ASSERT_TRUE(ed.save()) << ed.status();
  EXPECT_EQ(names_read(p, (dir.path / "names").string()), (std::vector<std::string>{"sun", "house", ""}));
  EXPECT_EQ(read_annotations((dir.path / "names" / "birds.annotations.json").string(), "birds.png").canvas_width_px,
            4000);
}

TEST(NamesEditor, WhatIsNotALibraryPictureHasNothingToName) {
  NamesEditor ed("/tmp");
  ed.open(NamesPicture{});
  EXPECT_FALSE(ed.is_open());
  EXPECT_EQ(ed.set_name("x", ""), "There is no library picture on show to name.");
  EXPECT_FALSE(ed.save());
  EXPECT_EQ(ed.last_save(), NamesSaved::failed);
}

}  // namespace
}  // namespace hk::app

namespace hk::app {
namespace {

// The Names tab's switch of the kiosk's guesses: with a face guessed over the round shape, the shape takes the
// guess's name; switched off, the names folder's sidecar says `guesses = false`, the kiosk reads it so
// (guesses_for), and the shape has no name; switched on again, it has.
TEST(NamesEditor, TheGuessesSwitchIsKeptInTheNamesFolderAndTheFaceGuessComesAndGoes) {
  TempDir dir("hk_names_guesses");
  NamesPicture p = picture_in(dir.path);
  // A face guessed around the circle (px 60..140 x 80..160).
  const Vec2 a = at(p.px_to_m, 55, 165), b = at(p.px_to_m, 145, 75);
  p.faces_m = {Aabb{{std::min(a.x, b.x), std::min(a.y, b.y)}, {std::max(a.x, b.x), std::max(a.y, b.y)}}};
  const fs::path folder = dir.path / "names";
  NamesEditor ed(folder.string());
  ed.open(p);
  ASSERT_TRUE(ed.guesses());
  ASSERT_EQ(ed.shape_region().size(), 3u);
  ASSERT_GE(ed.shape_region()[0], 0);
  EXPECT_EQ(ed.regions()[static_cast<std::size_t>(ed.shape_region()[0])].source, meaning::RegionSource::face);

  ASSERT_TRUE(ed.set_guesses(false)) << ed.status();
  const std::string sidecar = guesses_sidecar_in(folder.string(), p.picture_path);
  EXPECT_EQ(sidecar, (folder / "birds.toml").string());
  EXPECT_NE(read_file(sidecar).find("guesses = false"), std::string::npos);
  EXPECT_FALSE(guesses_for(p.picture_path, folder.string(), true)) << "the kiosk reads the switch";
  EXPECT_TRUE(ed.regions().empty());
  EXPECT_EQ(ed.shape_region()[0], -1);

  ASSERT_TRUE(ed.set_guesses(true)) << ed.status();
  EXPECT_TRUE(guesses_for(p.picture_path, folder.string(), false)) << "the names folder's switch wins";
  ASSERT_GE(ed.shape_region()[0], 0);
  // A names folder that is a file: the switch is not written and nothing changes.
  NamesEditor blocked((dir.path / "birds.png").string());
  blocked.open(p);
  EXPECT_FALSE(blocked.set_guesses(false));
  EXPECT_NE(blocked.status().find("Could not save the switch"), std::string::npos) << blocked.status();
  EXPECT_TRUE(blocked.guesses());
}

}  // namespace
}  // namespace hk::app
