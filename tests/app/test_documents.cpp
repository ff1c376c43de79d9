// Documents from USB sticks, end to end: PDF pages whose pictures give the
// PNG's own curves, text spoken not felt, explore on a PDF page, the `stick` command on a folder and on a
// real read-only mount of a loop device, the kiosk's stick service (insert, browse, a worker that crashes,
// remove mid-load, insert again), and the kiosk under Xvfb walking a stick.
#include <gtest/gtest.h>

#include <sched.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "child_process.hpp"
#include "kiosk_exe.hpp"
#include "pictures/documents.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_params.hpp"
#include "pictures/stick_service.hpp"
#include "runtime/runtime_params.hpp"
#include "test_paths.hpp"
#include "vision/pdf.hpp"

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace hk;
using namespace hk::app;

namespace {

using hk::test::sh;

const fs::path kData = HK_TEST_DATA_DIR;
const fs::path kHorsePdf = kData / "documents" / "horse_and_page.pdf";
const fs::path kSpecPdf = kData / "documents" / "shared-mime-info-spec.pdf";

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hk_doc_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

/// Fraction of the points of `b` within `tol_px` of a curve of `a`, distances in pixels of `a`'s image
/// (a's px_to_m), measured on a distance transform of a's polylines drawn at 4x resolution.
double fraction_within(const ImageScene& a, const ImageScene& b, double tol_px) {
  constexpr int kUp = 4;
  cv::Mat canvas(a.height_px * kUp, a.width_px * kUp, CV_8UC1, cv::Scalar(255));
  auto at = [&](Vec2 m) { return cv::Point2d((a.px_to_m.u_px(m.x) + 0.5) * kUp, (a.px_to_m.v_px(m.y) + 0.5) * kUp); };
  for (const Polyline& p : a.polylines) {
    for (std::size_t i = 0; i + 1 < p.points_m.size(); ++i)
      cv::line(canvas, at(p.points_m[i]), at(p.points_m[i + 1]), cv::Scalar(0), 1);
    if (p.closed && p.points_m.size() > 1)
      cv::line(canvas, at(p.points_m.back()), at(p.points_m.front()), cv::Scalar(0), 1);
  }
  cv::Mat dist;
  cv::distanceTransform(canvas, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  long n = 0, near = 0;
  for (const Polyline& p : b.polylines) {
    for (const Vec2& m : p.points_m) {
      const cv::Point2d c = at(m);
      const int x = std::clamp(static_cast<int>(c.x), 0, dist.cols - 1),
                y = std::clamp(static_cast<int>(c.y), 0, dist.rows - 1);
      ++n;
      near += dist.at<float>(y, x) / kUp <= tol_px;
    }
  }
  return n == 0 ? 0.0 : static_cast<double>(near) / static_cast<double>(n);
}

/// Default settings with a minute for the PDF worker instead of 5 s: these tests are about what a page
/// gives, not about time, and ctest runs them beside other suites (and the kiosk beside its software GL)
/// on a loaded 2-core machine under ASan.
config::Settings test_settings() {
  config::Settings s;
  s.stick.page_timeout_s = 60.0;
  return s;
}

/// The same for the command line: a settings file in `dir`, returned as " --config 'FILE'".
std::string generous_config(const fs::path& dir) {
  std::ofstream(dir / "generous.toml") << "[stick]\npage_timeout_s = 60.0\n";
  return " --config '" + (dir / "generous.toml").string() + "'";
}

/// The image attached read-only to a free loop device (losetup -r), made writable again and detached when
/// destroyed; dev is empty when the kernel refused.
struct LoopDevice {
  std::string dev;
  explicit LoopDevice(const fs::path& img) {
    FILE* p = ::popen(("losetup -r -f --show " + q(img) + " 2>/dev/null").c_str(), "r");
    char buf[128] = {};
    if (p && std::fgets(buf, sizeof buf, p)) dev = buf;
    if (p) ::pclose(p);
    while (!dev.empty() && (dev.back() == '\n' || dev.back() == ' ')) dev.pop_back();
  }
  ~LoopDevice() {
    // The kiosk set the device read-only (BLKROSET), and the flag outlives the attachment: clear it, so the
    // next user of this loop device finds it as the kernel hands it out.
    if (!dev.empty()) sh("blockdev --setrw " + dev + " 2>/dev/null; losetup -d " + dev + " 2>/dev/null");
  }
  LoopDevice(const LoopDevice&) = delete;
  LoopDevice& operator=(const LoopDevice&) = delete;
};

/// An 8 MB ext4 image of the folder `src` (mkfs.ext4 -d), its bytes when made, and a read-only loop device
/// over it (LoopDevice).
struct Ext4Stick {
  fs::path img;
  bool made = false;
  std::string before;
  std::unique_ptr<LoopDevice> loop;
  Ext4Stick(const fs::path& src, fs::path image) : img(std::move(image)) {
    made = sh("mkfs.ext4 -q -F -d " + q(src) + " " + q(img) + " 8M >/dev/null 2>&1") == 0;
    if (!made) return;
    before = slurp(img);
    loop = std::make_unique<LoopDevice>(img);
  }
};

std::vector<std::uint8_t> bytes_of(const fs::path& p) { return vision::read_input_file(p.string(), 1 << 30); }

}  // namespace

// The picture pages of horse_and_page.pdf (horse.png and page.png wrapped at 72 dpi by img2pdf) give the
// PNGs' own curves within a pixel, when drawn at that DPI and processed at the PNG's resolution with the
// same Canny thresholds and Canny alone (so geometry is compared, not the automatic thresholds or the texture
// test's decisions on slightly different tones).
TEST(PdfPages, PicturePagesGiveThePngsCurvesWithinAPixel) {
  const std::vector<std::uint8_t> pdf = bytes_of(kHorsePdf);
  for (const auto& [page, png, side] : {std::tuple{1, "horse.png", 400}, std::tuple{2, "page.png", 384}}) {
    config::Settings s = test_settings();
    s.vision.max_image_side_px = side;
    s.stick.page_max_dpi = 72.0;  // the DPI img2pdf embedded the pictures at: one page pixel per picture pixel
    s.vision.max_shapes = 1000;   // every curve: the pages' geometry is compared, not which 30 rank first
    s.vision.detector = "canny";  // nor which edges stand out from their surround (vision/texture.hpp)
    s.vision.ocr = "off";         // nor which words OCR reads and masks (page.png is a photo of a page of text)
    const ImageScene from_png = build_image_scene((kData / "images" / png).string(), s);
    s.vision.canny_low = from_png.canny_low;
    s.vision.canny_high = from_png.canny_high;
    const ImageScene from_pdf = build_pdf_page_scene(pdf, "horse_and_page.pdf", page, s);
    ASSERT_GT(from_png.polylines.size(), 0u) << png;
    EXPECT_EQ(from_pdf.pages, 2);
    EXPECT_NEAR(from_pdf.px_to_m.scale_m_per_px * from_pdf.width_px,
                from_png.px_to_m.scale_m_per_px * from_png.width_px, 1e-5)
        << "same page size in the workspace";
    if (page == 1) {
      EXPECT_GE(fraction_within(from_png, from_pdf, 1.0), 0.95)
          << png << ": points of the PDF page's curves within 1 px of the PNG's";
      EXPECT_GE(fraction_within(from_pdf, from_png, 1.0), 0.95)
          << png << ": points of the PNG's curves within 1 px of the PDF page's";
    } else {
      // img2pdf embedded page.png with its ICC profile, which poppler applies: the page's grey levels are
      // not the PNG's, and the faint edges of this unevenly lit text photo move or come and go (measured:
      // 91 % / 87 % of the points within 1 px, 95 % / 96 % within 3 px).
      EXPECT_GE(fraction_within(from_png, from_pdf, 1.0), 0.85) << png;
      EXPECT_GE(fraction_within(from_pdf, from_png, 1.0), 0.85) << png;
      EXPECT_GE(fraction_within(from_png, from_pdf, 3.0), 0.94) << png;
      EXPECT_GE(fraction_within(from_pdf, from_png, 3.0), 0.94) << png;
    }
  }
}

// A page of text: its words are masked from the edges (far fewer curves than the same page unmasked), the
// curves that remain do not run through the text, and the text is kept as blocks in the workspace.
TEST(PdfPages, TextIsSpokenNotFelt) {
  config::Settings s = test_settings();
  s.vision.ocr = "off";  // the text layer's words alone (without them the page would be read by OCR)
  const vision::PdfPage page =
      vision::render_pdf_page(bytes_of(kSpecPdf), "shared-mime-info-spec.pdf", 2, pdf_limits_from(s));
  ASSERT_GT(page.words.size(), 50u) << "page 2 of the specification is a page of text";
  const ImageScene masked = build_page_scene(page, "spec.pdf", 2, s);
  vision::PdfPage bare = page;
  bare.words.clear();
  bare.blocks.clear();
  const ImageScene unmasked = build_page_scene(bare, "spec.pdf", 2, s);
  EXPECT_LT(masked.polylines.size() * 5, unmasked.polylines.size())
      << masked.polylines.size() << " curves with the text masked, " << unmasked.polylines.size() << " without";
  ASSERT_FALSE(masked.text_blocks.empty());
  EXPECT_EQ(masked.text_words_masked, page.words.size());
  long inside = 0, points = 0;
  for (const Polyline& p : masked.polylines) {
    for (const Vec2& m : p.points_m) {
      ++points;
      for (const TextBlockM& b : masked.text_blocks) inside += b.contains(m);
    }
  }
  EXPECT_LE(inside, points / 20) << "curves left inside text blocks";
  for (const TextBlockM& b : masked.text_blocks) {
    EXPECT_LT(b.lo_m.x, b.hi_m.x);
    EXPECT_LT(b.lo_m.y, b.hi_m.y);
    EXPECT_GE(b.lo_m.x, -s.workspace.width_m / 2 - 1e-9);
    EXPECT_LE(b.hi_m.x, s.workspace.width_m / 2 + 1e-9);
    EXPECT_GE(b.lo_m.y, -s.workspace.height_m / 2 - 1e-9);
    EXPECT_LE(b.hi_m.y, s.workspace.height_m / 2 + 1e-9);
    EXPECT_FALSE(b.text.empty());
  }
}

TEST(PdfPages, TheBlockUnderTheHandIsTheOneReadAndFoundWithinReach) {
  std::vector<TextBlockM> blocks(2);
  blocks[0] = {0, {0.0, 0.010}, {0.030, 0.011}, "first line"};
  blocks[1] = {1, {0.0, 0.008}, {0.020, 0.009}, "second line"};
  EXPECT_EQ(text_block_at(blocks, {0.01, 0.0105})->id, 0) << "inside";
  EXPECT_EQ(text_block_at(blocks, {0.01, 0.0096})->id, 0) << "between the lines, nearer the first";
  EXPECT_EQ(text_block_at(blocks, {0.01, 0.0093})->id, 1) << "between the lines, nearer the second";
  EXPECT_EQ(text_block_at(blocks, {0.032, 0.0105})->id, 0) << "2 mm past its end: within reach";
  EXPECT_EQ(text_block_at(blocks, {0.035, 0.0105}), nullptr) << "5 mm past: out of reach";
  const std::vector<Aabb> r = text_block_regions(blocks);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_DOUBLE_EQ(r[1].hi.y, 0.009 + kTextBlockReachM);
  EXPECT_GE(r[1].hi.y, r[0].lo.y) << "neighbouring lines' regions meet, so the hand passes from one to the next";
}

TEST(PdfPages, TextMaskCoversEachWordGrownByAQuarterOfItsHeight) {
  const cv::Mat m = text_mask({100, 50}, {{"a", cv::Rect2d(10, 10, 20, 8)}, {"b", cv::Rect2d(95, 45, 20, 8)}});
  EXPECT_EQ(m.at<std::uint8_t>(8, 8), 255) << "grown by 2 px (8 / 4) up and left";
  EXPECT_EQ(m.at<std::uint8_t>(19, 31), 255) << "and down and right";
  EXPECT_EQ(m.at<std::uint8_t>(7, 20), 0) << "3 px above is outside";
  EXPECT_EQ(m.at<std::uint8_t>(14, 33), 0);
  EXPECT_EQ(m.at<std::uint8_t>(49, 99), 255) << "a word running off the page is clipped, not dropped";
  EXPECT_EQ(cv::countNonZero(text_mask({100, 50}, {})), 0);
}

// explore on a PDF page (DESIGN.md "Headless runs"): the contract files, with the page's text blocks.
TEST(ExploreDocument, PdfPageWritesTextBlocksAndRefusesBadPagesInOneLine) {
  const fs::path out = fresh_dir("explore");
  const std::string exe = HK_KIOSK_EXE;
  ASSERT_EQ(sh(exe + " explore " + q(kSpecPdf) + " --page 2 --out " + q(out) + generous_config(out) +
               " --duration 1 >/dev/null 2>" + q(out / "err.txt")),
            0)
      << slurp(out / "err.txt");
  const json scene = json::parse(slurp(out / "scene.json"));
  EXPECT_EQ(scene["page"], 2);
  EXPECT_EQ(scene["pages"], 17);
  ASSERT_TRUE(scene.contains("text_blocks"));
  ASSERT_FALSE(scene["text_blocks"].empty());
  int id = 0;
  for (const auto& b : scene["text_blocks"]) {
    EXPECT_EQ(b["id"], id++);
    ASSERT_EQ(b["bbox_m"].size(), 4u);
    EXPECT_LT(b["bbox_m"][0].get<double>(), b["bbox_m"][2].get<double>());
    EXPECT_LT(b["bbox_m"][1].get<double>(), b["bbox_m"][3].get<double>());
    EXPECT_FALSE(b["text"].get<std::string>().empty());
  }
  const json sum = json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(sum["document"]["text_blocks"], scene["text_blocks"].size());
  EXPECT_GT(sum["document"]["words_masked"].get<int>(), 50);
  EXPECT_TRUE(fs::exists(out / "overlay.png"));
  EXPECT_EQ(sh(exe + " explore " + q(kHorsePdf) + " --out " + q(out / "p1") + generous_config(out) +
               " --duration 0.2 >/dev/null 2>&1"),
            0)
      << "a PDF without --page: page 1";
  EXPECT_EQ(json::parse(slurp(out / "p1" / "scene.json"))["page"], 1);

  // Bad pages and files: a non-zero exit and one line naming the input and the limit.
  const std::vector<std::pair<std::string, std::string>> bad{
      {q(kHorsePdf) + " --page 3", "page 3"},
      {q(kData / "images" / "horse.png") + " --page 2", "not a PDF"},
  };
  for (const auto& [args, want] : bad) {
    const int status =
        sh(exe + " explore " + args + " --out " + q(out / "bad") + " >/dev/null 2>" + q(out / "err.txt"));
    const std::string err = slurp(out / "err.txt");
    EXPECT_NE(status, 0) << args;
    EXPECT_NE(err.find(want), std::string::npos) << args << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
  fs::remove_all(out);
}

// `haptic-kiosk stick DIR`: what the kiosk would offer, and what it refused and why, with exit 0.
TEST(StickCommand, ListsDocumentsWithPagesAndRefusalsWithReasons) {
  const fs::path dir = fresh_dir("stick_cmd");
  const fs::path stick = dir / "stick";
  fs::create_directories(stick / "holiday");
  fs::copy_file(kData / "images" / "horse.png", stick / "horse.png");
  fs::copy_file(kData / "images" / "butterfly.jpg", stick / "holiday" / "butterfly.jpg");
  fs::copy_file(kHorsePdf, stick / "two pages.pdf");
  std::ofstream(stick / "notes.pdf") << "not a PDF at all\n";
  fs::create_symlink("/etc/passwd", stick / "passwords.png");
  const std::string exe = HK_KIOSK_EXE;
  ASSERT_EQ(sh(exe + " stick " + q(stick) + generous_config(dir) + " --json " + q(dir / "stick.json") +
               " >/dev/null 2>" + q(dir / "err.txt")),
            0)
      << slurp(dir / "err.txt");
  const json j = json::parse(slurp(dir / "stick.json"));
  ASSERT_EQ(j["documents"].size(), 3u) << j.dump(2);
  EXPECT_EQ(j["documents"][0]["path"], "holiday/butterfly.jpg");
  EXPECT_EQ(j["documents"][0]["kind"], "image");
  EXPECT_EQ(j["documents"][0]["pages"], 1);
  EXPECT_EQ(j["documents"][1]["path"], "horse.png");
  EXPECT_EQ(j["documents"][2]["path"], "two pages.pdf");
  EXPECT_EQ(j["documents"][2]["kind"], "pdf");
  EXPECT_EQ(j["documents"][2]["pages"], 2);
  std::map<std::string, std::string> refused;
  for (const auto& r : j["refused"]) refused[r["path"]] = r["reason"];
  ASSERT_TRUE(refused.count("notes.pdf")) << j.dump(2);
  ASSERT_TRUE(refused.count("passwords.png")) << j.dump(2);
  EXPECT_NE(refused["passwords.png"].find("link"), std::string::npos) << refused["passwords.png"];
  EXPECT_TRUE(j["complete"].get<bool>());
  // Without --json the listing goes to standard output.
  ASSERT_EQ(sh(exe + " stick " + q(stick) + " >" + q(dir / "out.json") + " 2>/dev/null"), 0);
  EXPECT_EQ(json::parse(slurp(dir / "out.json"))["documents"].size(), 3u);
  // Not a folder: one line, non-zero.
  EXPECT_NE(sh(exe + " stick " + q(stick / "horse.png") + " >/dev/null 2>" + q(dir / "err.txt")), 0);
  const std::string err = slurp(dir / "err.txt");
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  fs::remove_all(dir);
}

TEST(StickCommand, APdfsOwnTitleIsListedWhenItIsOneAPersonWrote) {
  const fs::path dir = fresh_dir("stick_title");
  const fs::path stick = dir / "stick";
  fs::create_directories(stick);
  fs::copy_file(kData / "documents" / "titled.pdf", stick / "ring.pdf");
  fs::copy_file(kData / "bad" / "title_2000_bytes.pdf", stick / "long.pdf");
  fs::copy_file(kHorsePdf, stick / "plain.pdf");
  const StickListing l = list_stick(stick.string(), test_settings());
  ASSERT_EQ(l.documents.size(), 3u);
  std::map<std::string, std::string> titles;
  for (const ListedDocument& d : l.documents) titles[d.doc.display_name] = d.title;
  EXPECT_EQ(titles["ring.pdf"], "A ring, drawn for the hand \u2014 caf\u00e9 edition");
  EXPECT_EQ(titles["long.pdf"], "") << "2000 bytes: no title";
  EXPECT_EQ(titles["plain.pdf"], "") << "none in the file";
  const json j = stick_listing_json(l);
  for (const auto& d : j["documents"]) EXPECT_EQ(d.contains("title"), d["path"] == "ring.pdf") << d.dump();
  // Explore on the PDF itself: summary.json's document says it too.
  const std::string exe = HK_KIOSK_EXE;
  ASSERT_EQ(sh(exe + " explore " + q(stick / "ring.pdf") + " --out " + q(dir / "out") +
               " --duration 0.05 >/dev/null 2>" + q(dir / "err.txt")),
            0)
      << slurp(dir / "err.txt");
  EXPECT_EQ(json::parse(slurp(dir / "out" / "summary.json"))["document"]["title"],
            "A ring, drawn for the hand \u2014 caf\u00e9 edition");
  fs::remove_all(dir);
}

TEST(PdfTitle, WhatAnOfficeProgramWritesIsNoTitle) {
  EXPECT_EQ(pdf_title("  Annual report 2025 "), "Annual report 2025");
  EXPECT_EQ(pdf_title("Microsoft Word - notes.docx"), "");
  EXPECT_EQ(pdf_title("Microsoft PowerPoint - talk.pptx"), "");
  EXPECT_EQ(pdf_title("Untitled"), "");
  EXPECT_EQ(pdf_title("untitled document"), "");
  EXPECT_EQ(pdf_title("two\nlines"), "") << "a title is one line";
  EXPECT_EQ(pdf_title(std::string(201, 'x')), "") << "at most 200 bytes";
  EXPECT_EQ(pdf_title("bad \xff utf-8"), "");
  EXPECT_EQ(pdf_title("   "), "");
}

// `haptic-kiosk stick --device`: a real ext4 stick image on a read-only loop device, mounted by the kiosk's
// own code in a private mount namespace, scanned, unmounted; the image is byte for byte unchanged.
TEST(StickCommand, DeviceIsMountedReadOnlyScannedAndUnmounted) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root (losetup, mount); CI runs as root";
  if (sh("command -v mkfs.ext4 >/dev/null && command -v losetup >/dev/null && command -v unshare >/dev/null") != 0) {
    GTEST_SKIP() << "mkfs.ext4, losetup or unshare missing (scripts/install-deps.sh installs them)";
  }
  const fs::path dir = fresh_dir("stick_dev");
  fs::create_directories(dir / "src" / "docs");
  fs::copy_file(kData / "images" / "horse.png", dir / "src" / "horse.png");
  fs::copy_file(kHorsePdf, dir / "src" / "docs" / "horse_and_page.pdf");
  fs::create_symlink("/etc/shadow", dir / "src" / "shadow.png");
  const Ext4Stick stick(dir / "src", dir / "stick.img");
  ASSERT_TRUE(stick.made) << "mkfs.ext4 -d failed";
  if (stick.loop->dev.empty()) GTEST_SKIP() << "the kernel refused a loop device";
  const fs::path& img = stick.img;
  const std::string& before = stick.before;
  const std::string& loop = stick.loop->dev;
  const std::string exe = HK_KIOSK_EXE;
  const int status = sh("unshare -m --propagation private " + exe + " stick --device " + loop + generous_config(dir) +
                        " --mount-root " + q(dir / "mnt") + " --json " + q(dir / "stick.json") + " >/dev/null 2>" +
                        q(dir / "err.txt"));
  if (status != 0 && slurp(dir / "err.txt").find("unshare") != std::string::npos)
    GTEST_SKIP() << "no mount namespace here";
  ASSERT_EQ(status, 0) << slurp(dir / "err.txt");
  const json j = json::parse(slurp(dir / "stick.json"));
  EXPECT_EQ(j["device"]["filesystem"], "ext4");
  ASSERT_EQ(j["documents"].size(), 2u) << j.dump(2);
  EXPECT_EQ(j["documents"][0]["path"], "docs/horse_and_page.pdf");
  EXPECT_EQ(j["documents"][0]["pages"], 2);
  EXPECT_EQ(j["documents"][1]["path"], "horse.png");
  bool link_refused = false;
  for (const auto& r : j["refused"]) link_refused = link_refused || r["path"] == "shadow.png";
  EXPECT_TRUE(link_refused) << j.dump(2);
  EXPECT_EQ(slurp(img), before) << "nothing was written to the stick";
  EXPECT_TRUE(!fs::exists(dir / "mnt" / "0")) << "the mount point is removed after unmounting";
  fs::remove_all(dir);
}

namespace {

/// Waits (bounded) until the service has news or loads; the outcome is decided by what arrives, not by
/// the time taken.
template <class Poll>
auto wait_for(Poll poll) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  for (;;) {
    auto got = poll();
    if (!got.empty() || std::chrono::steady_clock::now() > deadline) return got;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace

// The kiosk's stick service on a folder standing in for a stick: inserted and listed, a PDF page and a
// picture built off the window thread, a worker that crashes reported as unreadable, taken out (later
// loads refused), inserted again under a new number.
TEST(StickService, InsertBrowseCrashRemoveInsertAgain) {
  const fs::path dir = fresh_dir("service");
  fs::copy_file(kData / "images" / "silhouette_3.png", dir / "a_shape.png");
  fs::copy_file(kHorsePdf, dir / "b_pages.pdf");
  config::Settings s = test_settings();
  StickService svc(s, nullptr, (dir / "mnt").string());
  svc.insert_folder(dir.string());
  std::vector<StickNews> news = wait_for([&] { return svc.poll_news(); });
  ASSERT_EQ(news.size(), 1u);
  ASSERT_EQ(news[0].kind, StickNews::Kind::Inserted);
  ASSERT_EQ(news[0].documents.size(), 2u);
  EXPECT_EQ(news[0].documents[1].pages, 2);
  const int stick = news[0].stick;

  svc.load(stick, 1, 2);
  std::vector<LoadedDocument> got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  ASSERT_TRUE(got[0].scene.has_value()) << got[0].reason;
  EXPECT_EQ(got[0].scene->page, 2);
  EXPECT_GT(got[0].scene->scene->curve_count(), 0u);
  svc.load(stick, 0, 1);
  got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  ASSERT_TRUE(got[0].scene.has_value()) << got[0].reason;
  EXPECT_EQ(got[0].scene->page, 0) << "a picture";

  svc.set_pdf_fault(vision::PdfFault::Crash);
  svc.load(stick, 1, 1);
  got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_FALSE(got[0].scene.has_value());
  EXPECT_NE(got[0].reason.find("signal"), std::string::npos) << got[0].reason;
  EXPECT_EQ(got[0].reason.find("b_pages.pdf"), std::string::npos)
      << "the reason is said after the name, not with it: " << got[0].reason;
  svc.set_pdf_fault(vision::PdfFault::None);

  svc.remove_folder();
  news = wait_for([&] { return svc.poll_news(); });
  ASSERT_EQ(news.size(), 1u);
  EXPECT_EQ(news[0].kind, StickNews::Kind::Removed);
  svc.load(stick, 1, 1);
  got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_FALSE(got[0].scene.has_value()) << "a stick taken out is not read";

  svc.insert_folder(dir.string());
  news = wait_for([&] { return svc.poll_news(); });
  ASSERT_EQ(news.size(), 1u);
  EXPECT_EQ(news[0].kind, StickNews::Kind::Inserted);
  EXPECT_NE(news[0].stick, stick) << "every insertion is a new stick";
  svc.forget();
  svc.load(news[0].stick, 0, 1);
  got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_FALSE(got[0].scene.has_value()) << "a forgotten stick is not read";
  fs::remove_all(dir);
}

/// Waits (bounded) until `ready()` holds; the outcome is decided by the state reached, not by the time taken.
template <class Ready>
bool wait_until(Ready ready) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!ready()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

/// A folder standing in for a stick, inserted: a_shape.png (document 0) and b_pages.pdf (document 1, two
/// pages). Returns the stick's number (0 when the insertion failed).
int insert_shape_and_pages(StickService& svc, const fs::path& dir) {
  fs::copy_file(kData / "images" / "silhouette_3.png", dir / "a_shape.png");
  fs::copy_file(kHorsePdf, dir / "b_pages.pdf");
  svc.insert_folder(dir.string());
  const std::vector<StickNews> news = wait_for([&] { return svc.poll_news(); });
  if (news.size() != 1 || news[0].kind != StickNews::Kind::Inserted || news[0].documents.size() != 2) return 0;
  return news[0].stick;
}

// Between requests the loader builds the pages Next and Previous lead to; Next then gets its page at once,
// without a build of its own; new settings drop what was built ahead, and [kiosk] prefetch_mb = 0 builds
// nothing ahead.
TEST(StickService, NextAndPreviousPagesAreBuiltAheadAndHandedOverAtOnce) {
  const fs::path dir = fresh_dir("service_ahead");
  config::Settings s = test_settings();
  StickService svc(s, nullptr, (dir / "mnt").string());
  const int stick = insert_shape_and_pages(svc, dir);
  ASSERT_NE(stick, 0);

  svc.load(stick, 1, 1);
  std::vector<LoadedDocument> got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  ASSERT_TRUE(got[0].scene.has_value()) << got[0].reason;
  EXPECT_EQ(svc.loads_started(), 1);
  // The neighbours of the PDF's first page: its second page (Next) and the picture before it (Previous).
  ASSERT_TRUE(wait_until([&] { return svc.pages_ahead() == 2; })) << svc.pages_ahead() << " pages built ahead";
  EXPECT_EQ(svc.ahead_started(), 2);

  svc.load(stick, 1, 2);
  got = svc.poll_loaded();  // handed over inside load(): no wait
  ASSERT_EQ(got.size(), 1u) << "a page built ahead is there at once";
  ASSERT_TRUE(got[0].scene.has_value());
  EXPECT_EQ(got[0].scene->page, 2);
  EXPECT_EQ(got[0].document, 1);
  EXPECT_EQ(got[0].load_ms, 0.0);
  EXPECT_GT(got[0].scene->scene->curve_count(), 0u);
  EXPECT_EQ(svc.loads_started(), 1) << "Next needed no build of its own";
  // From page 2: Next wraps to the picture (kept: it was built ahead already), Previous is page 1 (built again).
  ASSERT_TRUE(wait_until([&] { return svc.pages_ahead() == 2; }));
  EXPECT_EQ(svc.ahead_started(), 3);

  s.kiosk.prefetch_mb = 0;
  svc.set_settings(s);
  EXPECT_EQ(svc.pages_ahead(), 0) << "pages built with other settings are dropped";
  svc.load(stick, 0, 1);
  got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  ASSERT_TRUE(got[0].scene.has_value()) << got[0].reason;
  EXPECT_EQ(svc.loads_started(), 2) << "the picture built ahead went with the old settings: built when asked for";
  EXPECT_EQ(svc.pages_ahead(), 0);
  EXPECT_EQ(svc.ahead_started(), 3) << "prefetch_mb = 0: nothing built ahead";
  fs::remove_all(dir);
}

// A request for the page being built ahead takes that build over (no second build), and a page that cannot
// be drawn is said as for any request; a stick taken out drops its pages built ahead.
TEST(StickService, ARequestForThePageBeingBuiltAheadTakesItOverUntilAnotherIsAsked) {
  const fs::path dir = fresh_dir("service_takeover");
  config::Settings s = test_settings();
  s.stick.page_timeout_s = 3.0;  // the hanging worker below is stopped after this
  StickService svc(s, nullptr, (dir / "mnt").string());
  svc.set_pdf_fault(vision::PdfFault::Hang);  // every PDF page hangs until the page limit; the picture is drawn
  const int stick = insert_shape_and_pages(svc, dir);
  ASSERT_NE(stick, 0);

  svc.load(stick, 0, 1);
  std::vector<LoadedDocument> got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  ASSERT_TRUE(got[0].scene.has_value()) << got[0].reason;
  // Next from the picture is the PDF's first page: built ahead first, its worker hanging for 3 s.
  ASSERT_TRUE(wait_until([&] { return svc.ahead_started() >= 1; }));
  svc.load(stick, 1, 1);
  got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].document, 1);
  EXPECT_EQ(got[0].page, 1);
  EXPECT_FALSE(got[0].scene.has_value()) << "the hanging page is unreadable";
  EXPECT_FALSE(got[0].reason.empty());
  EXPECT_EQ(svc.loads_started(), 1) << "the request took the build ahead over instead of starting its own";

  // Next to page 2 takes its build ahead over; Previous back to the picture before that build ends leaves
  // page 2 unwanted: only the picture comes.
  ASSERT_TRUE(wait_until([&] { return svc.ahead_started() >= 2; })) << "page 2 is built ahead, hanging";
  svc.load(stick, 1, 2);
  svc.load(stick, 0, 1);
  got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].document, 0) << "page " << got[0].page << " of document " << got[0].document
                                << " was handed over after it was passed by";
  EXPECT_TRUE(got[0].scene.has_value()) << got[0].reason;

  svc.set_pdf_fault(vision::PdfFault::None);
  ASSERT_TRUE(wait_until([&] { return svc.pages_ahead() >= 1; })) << "the neighbours of page 1 are built ahead";
  svc.remove_folder();
  const std::vector<StickNews> news = wait_for([&] { return svc.poll_news(); });
  ASSERT_EQ(news.size(), 1u);
  EXPECT_EQ(news[0].kind, StickNews::Kind::Removed);
  EXPECT_EQ(svc.pages_ahead(), 0) << "a stick taken out keeps nothing built ahead";
  svc.load(stick, 1, 2);
  got = wait_for([&] { return svc.poll_loaded(); });
  ASSERT_EQ(got.size(), 1u);
  EXPECT_FALSE(got[0].scene.has_value()) << "a stick taken out is not read, even a page built ahead";
  fs::remove_all(dir);
}

// The kiosk under Xvfb with a folder inserted as a stick: the summary and first document are said, Next
// walks to the PDF's pages (the second, a photo of a page of text, is read by OCR: said at once, then that its
// text is ready), Describe on a page says what it holds, taking the stick out goes back to the library (its
// speech log, one "say:" line per message).
TEST(KioskScreen, StickIsBrowsedPageByPageAndTakenOut) {
  if (sh("command -v xvfb-run >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "xvfb-run is not installed (scripts/install-deps.sh installs it)";
  const fs::path dir = fresh_dir("kiosk_stick");
  fs::create_directories(dir / "library");
  fs::create_directories(dir / "stick");
  fs::copy_file(kData / "images" / "silhouette_3.png", dir / "library" / "shape.png");
  fs::copy_file(kData / "images" / "horse.png", dir / "stick" / "a horse.png");
  fs::copy_file(kHorsePdf, dir / "stick" / "b two pages.pdf");
  std::ofstream(dir / "script.txt") << "1 stick " << (dir / "stick").string()
                                    << "\n2 wait_loaded\n3 key next\n4 wait_loaded\n"
                                    << "5 key next\n6 wait_loaded\n7 key describe\n8 unstick\n9 wait_loaded\n";
  const std::string exe = HK_KIOSK_EXE;
  ASSERT_EQ(
      sh("ASAN_OPTIONS=detect_leaks=0 timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' " + exe + " --no-hotplug" +
         generous_config(dir) + " --library " + q(dir / "library") + " --script " + q(dir / "script.txt") +
         " --screenshot " + q(dir / "end.png") + " --frames 40 >" + q(dir / "log.txt") + " 2>&1"),
      0)
      << slurp(dir / "log.txt");
  std::vector<std::string> said;
  std::istringstream log(slurp(dir / "log.txt"));
  for (std::string line; std::getline(log, line);) {
    const auto at = line.find("say: ");
    if (at != std::string::npos) said.push_back(line.substr(at + 5));
  }
  const std::vector<std::string> want_prefix{
      "A USB stick with 2 documents: a picture and a PDF of 2 pages. Press the Right arrow to go through them. "
      "Document 1 of 2, a horse. It has",
      "Page 1 of 2 of b two pages. It has no text and",
      "Page 2 of 2 of b two pages. Reading the text.",
      "The text is ready. It has",
      "People nearby can hear your document. Press the P key to pause it, or the End key to stop. It has",
      "The USB stick was taken out. Back to the picture library. Picture 1 of 1."};
  ASSERT_EQ(said.size(), want_prefix.size()) << slurp(dir / "log.txt");
  for (std::size_t i = 0; i < said.size(); ++i) EXPECT_EQ(said[i].rfind(want_prefix[i], 0), 0u) << said[i];
  fs::remove_all(dir);
}

// A hostile stick through the `stick` command: every bad PDF refused or capped with its reason, in one
// line each, the scan complete, the kiosk unharmed (exit 0).
TEST(StickCommand, HostilePdfsAreRefusedOrCappedWithReasons) {
  const fs::path dir = fresh_dir("hostile");
  const fs::path stick = dir / "stick";
  fs::create_directories(stick);
  for (const char* f :
       {"empty.pdf", "text_named.pdf", "truncated.pdf", "locked.pdf", "pages_5000.pdf", "page_14400pt.pdf"}) {
    fs::copy_file(kData / "bad" / f, stick / f);
  }
  const std::string exe = HK_KIOSK_EXE;
  ASSERT_EQ(sh(exe + " stick " + q(stick) + generous_config(dir) + " --json " + q(dir / "stick.json") +
               " >/dev/null 2>" + q(dir / "err.txt")),
            0)
      << slurp(dir / "err.txt");
  const json j = json::parse(slurp(dir / "stick.json"));
  std::map<std::string, std::string> refused;
  for (const auto& r : j["refused"]) refused[r["path"]] = r["reason"];
  const std::map<std::string, std::string> want{{"empty.pdf", "empty"},
                                                {"text_named.pdf", "not a picture or PDF"},
                                                {"truncated.pdf", "pdf 'truncated.pdf'"},
                                                {"locked.pdf", "password"}};
  for (const auto& [file, reason] : want) {
    ASSERT_TRUE(refused.count(file)) << file << " not refused: " << j.dump(2);
    EXPECT_NE(refused[file].find(reason), std::string::npos) << file << ": " << refused[file];
    EXPECT_EQ(refused[file].find('\n'), std::string::npos);
  }
  ASSERT_EQ(j["documents"].size(), 2u) << j.dump(2);
  EXPECT_EQ(j["documents"][0]["path"], "page_14400pt.pdf") << "the largest page is offered: it is drawn at low DPI";
  EXPECT_EQ(j["documents"][1]["path"], "pages_5000.pdf");
  EXPECT_EQ(j["documents"][1]["pages"], 1000) << "capped at [stick] max_pdf_pages";
  EXPECT_EQ(j["documents"][1]["pages_in_file"], 5000);
  EXPECT_TRUE(j["complete"].get<bool>());
  fs::remove_all(dir);
}

namespace {

/// Runs `body` in a forked child inside a private mount namespace; returns what it reports ("" = passed,
/// "SKIP: ..." = could not run here, else the failure). The test process's own mounts are never touched.
std::string in_mount_namespace(const std::function<std::string()>& body) {
  return test::run_in_child(
      [&]() -> std::string {
        if (::unshare(CLONE_NEWNS) != 0 || ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0)
          return "SKIP: no private mount namespace here";
        return body();
      },
      "SKIP: no pipe or child process");
}

/// The first news, waiting (bounded) for it.
std::optional<StickNews> next_news(StickService& svc) {
  std::vector<StickNews> n = wait_for([&] { return svc.poll_news(); });
  if (n.empty()) return std::nullopt;
  return n.front();
}

}  // namespace

// Hot-plug with a fake event source and a real device: a read-only loop
// device "inserted" is mounted by the kiosk's own code and listed; a page is browsed; the stick is taken
// out while a page is still being drawn (the worker made to hang), and the removal is not held up by it;
// inserted again, it is a new stick. The image is unchanged.
// A write onto the stick in the kiosk (a take-home copy): none without a stick; a folder stick is written in
// place; a real ext4 stick, mounted by the kiosk's own code, is refused as not FAT or exFAT before anything is
// touched (the image is unchanged) and the writer never runs; taken out, there is no stick again.
TEST(StickService, WritesGoOnlyToAStickInTheKioskAndOnlyIfFatOrExfat) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root (losetup, mount); CI runs as root";
  if (sh("command -v mkfs.ext4 >/dev/null && command -v losetup >/dev/null") != 0)
    GTEST_SKIP() << "mkfs.ext4 or losetup missing";
  const fs::path dir = fresh_dir("stick_write");
  fs::create_directories(dir / "src");
  fs::copy_file(kData / "images" / "silhouette_3.png", dir / "src" / "shape.png");
  const Ext4Stick stick(dir / "src", dir / "stick.img");
  ASSERT_TRUE(stick.made) << "mkfs.ext4 -d failed";
  if (stick.loop->dev.empty()) GTEST_SKIP() << "the kernel refused a loop device";
  const std::string& loop = stick.loop->dev;
  const fs::path folder_stick = dir / "folder";
  fs::create_directories(folder_stick);

  const std::string result = in_mount_namespace([&]() -> std::string {
    auto events = std::make_unique<sticks::FakeBlockEventSource>();
    sticks::FakeBlockEventSource* fake = events.get();
    StickService svc(test_settings(), std::move(events), (dir / "mnt").string());
    if (!svc.can_mount()) return "SKIP: no CAP_SYS_ADMIN";
    int written = 0;
    const auto writer = [&](const std::string& top) {
      ++written;
      std::ofstream(fs::path(top) / "copy.txt") << "a copy";
    };
    if (svc.stick_in()) return "a stick is in before any was inserted";
    if (svc.write_to_stick(writer).get().kind != StickWriteOutcome::Kind::NoStick) return "no stick: not NoStick";

    svc.insert_folder(folder_stick.string());
    std::optional<StickNews> n = next_news(svc);
    if (!n || !svc.stick_in()) return "folder: not in";
    if (svc.write_to_stick(writer).get().kind != StickWriteOutcome::Kind::Written || written != 1)
      return "folder: not written";
    if (slurp(folder_stick / "copy.txt") != "a copy") return "folder: the file is not there";
    svc.remove_folder();
    n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Removed || svc.stick_in()) return "folder: still in after removal";

    fake->push({sticks::BlockEvent::Action::Add, loop, ""});
    n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Inserted || !svc.stick_in()) return "ext4: not inserted";
    const StickWriteOutcome o = svc.write_to_stick(writer).get();
    if (o.kind != StickWriteOutcome::Kind::Format) return "ext4: expected Format, got: " + o.error;
    if (o.error.find("(ext4) is not one the kiosk writes") == std::string::npos) return "ext4: " + o.error;
    if (written != 1) return "ext4: the writer ran";
    fake->push({sticks::BlockEvent::Action::Remove, loop, ""});
    n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Removed || svc.stick_in()) return "ext4: still in after removal";
    return "";
  });
  if (result.rfind("SKIP: ", 0) == 0) GTEST_SKIP() << result.substr(6);
  EXPECT_EQ(result, "");
  EXPECT_EQ(slurp(stick.img), stick.before) << "nothing was written to the ext4 stick";
  fs::remove_all(dir);
}

TEST(StickService, HotPlugInsertBrowseRemoveMidRenderInsertAgain) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root (losetup, mount); CI runs as root";
  if (sh("command -v mkfs.ext4 >/dev/null && command -v losetup >/dev/null") != 0)
    GTEST_SKIP() << "mkfs.ext4 or losetup missing";
  const fs::path dir = fresh_dir("hotplug");
  fs::create_directories(dir / "src");
  fs::copy_file(kHorsePdf, dir / "src" / "pages.pdf");
  fs::copy_file(kData / "images" / "silhouette_3.png", dir / "src" / "shape.png");
  const Ext4Stick stick(dir / "src", dir / "stick.img");
  ASSERT_TRUE(stick.made) << "mkfs.ext4 -d failed";
  if (stick.loop->dev.empty()) GTEST_SKIP() << "the kernel refused a loop device";
  const fs::path& img = stick.img;
  const std::string& before = stick.before;
  const std::string& loop = stick.loop->dev;

  const std::string result = in_mount_namespace([&]() -> std::string {
    auto events = std::make_unique<sticks::FakeBlockEventSource>();
    sticks::FakeBlockEventSource* fake = events.get();
    config::Settings s = test_settings();
    s.stick.page_timeout_s = 10.0;  // the page drawn first must be done within it, and the hanging worker lasts it
    StickService svc(s, std::move(events), (dir / "mnt").string());
    if (!svc.can_mount()) return "SKIP: no CAP_SYS_ADMIN";
    fake->push({sticks::BlockEvent::Action::Add, loop, ""});
    std::optional<StickNews> n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Inserted)
      return "insert: no Inserted news" + (n ? " (" + n->reason + ")" : std::string());
    if (n->documents.size() != 2 || n->documents[0].pages != 2)
      return "insert: expected pages.pdf (2 pages) and shape.png";
    const int first = n->stick;
    svc.load(first, 0, 2);
    std::vector<LoadedDocument> d = wait_for([&] { return svc.poll_loaded(); });
    if (d.size() != 1 || !d[0].scene || d[0].scene->page != 2)
      return "browse: page 2 not built: " + (d.empty() ? "" : d[0].reason);

    svc.set_pdf_fault(vision::PdfFault::Hang);
    svc.load(first, 0, 1);  // drawn by a worker that hangs until the 10 s page limit
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (svc.loads_started() < 2 && std::chrono::steady_clock::now() < until) std::this_thread::yield();
    if (svc.loads_started() < 2) return "remove: the second load never started";
    fake->push({sticks::BlockEvent::Action::Remove, loop, ""});
    n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Removed) return "remove: no Removed news";
    if (!svc.poll_loaded().empty()) return "remove: the hanging page finished before the removal was reported";
    d = wait_for([&] { return svc.poll_loaded(); });
    if (d.size() != 1 || d[0].scene) return "remove: the hanging page should end unreadable";
    svc.set_pdf_fault(vision::PdfFault::None);
    if (fs::exists(dir / "mnt" / "0")) return "remove: mount point left behind";

    fake->push({sticks::BlockEvent::Action::Add, loop, ""});
    n = next_news(svc);
    if (!n || n->kind != StickNews::Kind::Inserted || n->stick == first) return "insert again: expected a new stick";
    svc.load(n->stick, 1, 1);
    d = wait_for([&] { return svc.poll_loaded(); });
    if (d.size() != 1 || !d[0].scene) return "insert again: shape.png not built";
    return "";
  });
  if (result.rfind("SKIP: ", 0) == 0) GTEST_SKIP() << result.substr(6);
  EXPECT_EQ(result, "");
  EXPECT_EQ(slurp(img), before) << "nothing was written to the stick";
  fs::remove_all(dir);
}
