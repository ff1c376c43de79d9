// The scene cache (app/pictures/include/pictures/scene_cache.hpp) on real scenes: a stored scene loads back equal in
// every kept field with the same collision trees; keys follow the picture's bytes and exactly the settings that shape a
// scene; corrupt, stale and hostile entries are refused and removed without a crash; a folder that cannot be
// written costs the store only; the size cap removes the least recently used entry; "off" touches nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <sodium.h>
#include <sys/resource.h>
#include <unistd.h>
#include <csignal>

#include <opencv2/core.hpp>

#include "pictures/image_scene.hpp"
#include "pictures/scene_cache.hpp"
#include "test_paths.hpp"
#include "without_file_override.hpp"

namespace hk::app {
namespace {

namespace fs = std::filesystem;

const std::string kImages = std::string(HK_TEST_DATA_DIR) + "/images/";

std::vector<std::uint8_t> read_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& p, const std::vector<std::uint8_t>& b) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

/// The horse's scene with the default settings, built once for the whole suite.
const ImageScene& horse() {
  static const ImageScene is = build_image_scene(kImages + "horse.png", config::Settings{});
  return is;
}

/// A copy of `is` (ImageScene holds a unique_ptr): every field, the Scene rebuilt the way the build did.
ImageScene copy_of(const ImageScene& is, const config::Settings& s) {
  ImageScene c;
  c.image_path = is.image_path;
  c.page = is.page;
  c.pages = is.pages;
  c.document_title = is.document_title;
  c.picture = is.picture.clone();
  c.text_blocks = is.text_blocks;
  c.ocr = is.ocr;
  c.text_likely = is.text_likely;
  c.text_words_masked = is.text_words_masked;
  c.file_notes = is.file_notes;
  c.render_dpi = is.render_dpi;
  c.worker_ms = is.worker_ms;
  c.worker_max_rss_kb = is.worker_max_rss_kb;
  c.width_px = is.width_px;
  c.height_px = is.height_px;
  c.px_to_m = is.px_to_m;
  c.chains_texture = is.chains_texture;
  c.chains_found = is.chains_found;
  c.thin_line_pairs_merged = is.thin_line_pairs_merged;
  c.chains_after_thin_lines = is.chains_after_thin_lines;
  c.gaps_closed = is.gaps_closed;
  c.chains_closed_by_gaps = is.chains_closed_by_gaps;
  c.chains_after_gaps = is.chains_after_gaps;
  c.chains_too_short = is.chains_too_short;
  c.chains_along_border = is.chains_along_border;
  c.chains_over_max_shapes = is.chains_over_max_shapes;
  c.chains_over_budget = is.chains_over_budget;
  c.segments_before_budget = is.segments_before_budget;
  c.segments_after_budget = is.segments_after_budget;
  c.canny_low = is.canny_low;
  c.canny_high = is.canny_high;
  c.detector = is.detector;
  c.tones = is.tones;
  c.line_drawing = is.line_drawing;
  c.polylines = is.polylines;
  c.strength = is.strength;
  c.descriptors = is.descriptors;
  c.scene = std::make_unique<Scene>(Scene::build(c.polylines, s.haptics.max_levels));
  c.times = is.times;
  return c;
}

/// Every kept field of `b` equals `a`'s (doubles exactly), its Scene has the same curves and level-0 points,
/// and its picture has the same size and close pixels (JPEG).
void expect_same(const ImageScene& a, const ImageScene& b) {
  EXPECT_EQ(a.image_path, b.image_path);
  EXPECT_EQ(a.page, b.page);
  EXPECT_EQ(a.file_notes.title, b.file_notes.title);
  EXPECT_EQ(a.file_notes.description, b.file_notes.description);
  EXPECT_EQ(a.pages, b.pages);
  EXPECT_EQ(a.document_title, b.document_title);
  ASSERT_EQ(a.text_blocks.size(), b.text_blocks.size());
  for (std::size_t i = 0; i < a.text_blocks.size(); ++i) {
    const TextBlockM &x = a.text_blocks[i], &y = b.text_blocks[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.lo_m.x, y.lo_m.x);
    EXPECT_EQ(x.lo_m.y, y.lo_m.y);
    EXPECT_EQ(x.hi_m.x, y.hi_m.x);
    EXPECT_EQ(x.hi_m.y, y.hi_m.y);
    EXPECT_EQ(x.text, y.text);
    EXPECT_EQ(x.source, y.source);
    EXPECT_EQ(x.confidence, y.confidence);
  }
  EXPECT_EQ(a.ocr.ran, b.ocr.ran);
  EXPECT_EQ(a.ocr.why, b.ocr.why);
  EXPECT_EQ(a.ocr.words, b.ocr.words);
  EXPECT_EQ(a.ocr.mean_confidence, b.ocr.mean_confidence);
  EXPECT_EQ(a.ocr.ms, b.ocr.ms);
  EXPECT_EQ(a.ocr.worker_max_rss_kb, b.ocr.worker_max_rss_kb);
  EXPECT_FALSE(b.text_pending);
  EXPECT_FALSE(b.with_text);
  EXPECT_EQ(a.text_likely, b.text_likely);
  EXPECT_EQ(a.text_words_masked, b.text_words_masked);
  EXPECT_EQ(a.render_dpi, b.render_dpi);
  EXPECT_EQ(a.worker_ms, b.worker_ms);
  EXPECT_EQ(a.worker_max_rss_kb, b.worker_max_rss_kb);
  EXPECT_EQ(a.width_px, b.width_px);
  EXPECT_EQ(a.height_px, b.height_px);
  EXPECT_EQ(a.file_width_px, b.file_width_px);
  EXPECT_EQ(a.file_height_px, b.file_height_px);
  EXPECT_EQ(a.decode_scale, b.decode_scale);
  EXPECT_EQ(a.px_to_m.scale_m_per_px, b.px_to_m.scale_m_per_px);
  EXPECT_EQ(a.px_to_m.offset_x_m, b.px_to_m.offset_x_m);
  EXPECT_EQ(a.px_to_m.offset_y_m, b.px_to_m.offset_y_m);
  ASSERT_EQ(a.descriptors.size(), b.descriptors.size());
  for (std::size_t i = 0; i < a.descriptors.size(); ++i) {
    const meaning::ShapeDescriptor &x = a.descriptors[i], &y = b.descriptors[i];
    EXPECT_EQ(x.form.form, y.form.form);
    EXPECT_EQ(x.form.corners, y.form.corners);
    EXPECT_EQ(x.has_colour, y.has_colour);
    EXPECT_EQ(x.colour.colour, y.colour.colour);
    EXPECT_EQ(x.colour.shade, y.colour.shade);
    EXPECT_EQ(x.size_cm, y.size_cm);
    EXPECT_EQ(x.length_m, y.length_m);
    EXPECT_EQ(x.speck, y.speck);
  }
  EXPECT_EQ(a.chains_texture, b.chains_texture);
  EXPECT_EQ(a.chains_found, b.chains_found);
  EXPECT_EQ(a.thin_line_pairs_merged, b.thin_line_pairs_merged);
  EXPECT_EQ(a.chains_after_thin_lines, b.chains_after_thin_lines);
  EXPECT_EQ(a.gaps_closed, b.gaps_closed);
  EXPECT_EQ(a.chains_closed_by_gaps, b.chains_closed_by_gaps);
  EXPECT_EQ(a.chains_after_gaps, b.chains_after_gaps);
  EXPECT_EQ(a.chains_too_short, b.chains_too_short);
  EXPECT_EQ(a.chains_along_border, b.chains_along_border);
  EXPECT_EQ(a.chains_over_max_shapes, b.chains_over_max_shapes);
  EXPECT_EQ(a.chains_over_budget, b.chains_over_budget);
  EXPECT_EQ(a.segments_before_budget, b.segments_before_budget);
  EXPECT_EQ(a.segments_after_budget, b.segments_after_budget);
  EXPECT_EQ(a.canny_low, b.canny_low);
  EXPECT_EQ(a.canny_high, b.canny_high);
  EXPECT_EQ(a.detector, b.detector);
  EXPECT_EQ(a.tones.two_tone, b.tones.two_tone);
  EXPECT_EQ(a.tones.threshold, b.tones.threshold);
  EXPECT_EQ(a.tones.dark_mean, b.tones.dark_mean);
  EXPECT_EQ(a.tones.light_mean, b.tones.light_mean);
  EXPECT_EQ(a.tones.near_share, b.tones.near_share);
  EXPECT_EQ(a.tones.ink_width_px, b.tones.ink_width_px);
  EXPECT_EQ(a.line_drawing, b.line_drawing);
  ASSERT_EQ(a.polylines.size(), b.polylines.size());
  for (std::size_t i = 0; i < a.polylines.size(); ++i) {
    EXPECT_EQ(a.polylines[i].closed, b.polylines[i].closed);
    ASSERT_EQ(a.polylines[i].points_m.size(), b.polylines[i].points_m.size());
    for (std::size_t k = 0; k < a.polylines[i].points_m.size(); ++k) {
      EXPECT_EQ(a.polylines[i].points_m[k].x, b.polylines[i].points_m[k].x);
      EXPECT_EQ(a.polylines[i].points_m[k].y, b.polylines[i].points_m[k].y);
    }
  }
  EXPECT_EQ(a.strength, b.strength);
  EXPECT_EQ(a.times.load_ms, b.times.load_ms);
  EXPECT_EQ(a.times.edges_ms, b.times.edges_ms);
  EXPECT_EQ(a.times.linking_ms, b.times.linking_ms);
  EXPECT_EQ(a.times.thin_lines_ms, b.times.thin_lines_ms);
  EXPECT_EQ(a.times.gaps_ms, b.times.gaps_ms);
  // The trees: the same curves, the same level-0 points bit for bit.
  ASSERT_TRUE(b.scene);
  ASSERT_EQ(a.scene->curve_count(), b.scene->curve_count());
  EXPECT_EQ(a.scene->total_segments(0), b.scene->total_segments(0));
  for (std::size_t c = 0; c < a.scene->curve_count(); ++c) {
    const CurveInfo &x = a.scene->curve(c), &y = b.scene->curve(c);
    EXPECT_EQ(a.scene->source_index(c), b.scene->source_index(c));
    EXPECT_EQ(x.closed, y.closed);
    EXPECT_EQ(x.levels, y.levels);
    ASSERT_EQ(x.point_count[0], y.point_count[0]);
    const Vec2* px = a.scene->slot_points(x.point_offset[0]);
    const Vec2* py = b.scene->slot_points(y.point_offset[0]);
    for (std::uint32_t i = 0; i < x.point_count[0]; ++i) {
      EXPECT_EQ(px[i].x, py[i].x);
      EXPECT_EQ(px[i].y, py[i].y);
    }
  }
  ASSERT_EQ(a.picture.empty(), b.picture.empty());
  if (!a.picture.empty()) {
    ASSERT_EQ(a.picture.size(), b.picture.size());
    ASSERT_EQ(b.picture.type(), CV_8UC3);
    const double mean_abs = cv::norm(a.picture, b.picture, cv::NORM_L1) / static_cast<double>(a.picture.total() * 3);
    EXPECT_LT(mean_abs, 3.0) << "JPEG quality 90 keeps the pixels within a few grey levels on average";
  }
}

/// A folder of its own under the temporary folder, removed (with its permissions restored) after the test.
class SceneCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    root_ =
        fs::temp_directory_path() / ("hk_scene_cache_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    dir_ = (root_ / "cache" / "scenes").string();
  }
  void TearDown() override {
    std::error_code ec;
    for (fs::recursive_directory_iterator it(root_, ec), end; !ec && it != end; it.increment(ec))
      if (it->is_directory()) fs::permissions(it->path(), fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(root_, ec);
  }
  /// Key of the horse's file bytes with `tag` appended: distinct keys for one scene.
  static std::string key_of(const std::string& tag, const config::Settings& s = {}) {
    std::vector<std::uint8_t> b = read_bytes(kImages + "horse.png");
    b.insert(b.end(), tag.begin(), tag.end());
    return SceneCache::key(b, s);
  }
  /// Files in `dir` (none when it does not exist).
  static std::vector<std::string> files_in(const std::string& dir) {
    std::vector<std::string> out;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
      out.push_back(it->path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
  fs::path root_;
  std::string dir_;
  config::Settings s_;
};

TEST_F(SceneCacheTest, StoredSceneLoadsBackEqualInEveryKeptField) {
  SceneCache cache(dir_);
  const std::string key = key_of("");
  ASSERT_TRUE(cache.store(key, horse()));
  EXPECT_EQ(files_in(dir_), std::vector<std::string>{key + ".scene"});
  EXPECT_EQ(fs::status(dir_).permissions() & fs::perms::all, fs::perms::owner_all)
      << "the folder is created with mode 0700";
  const std::optional<ImageScene> back = cache.load(key, s_);
  ASSERT_TRUE(back);
  ASSERT_GT(horse().polylines.size(), 0u);
  expect_same(horse(), *back);
}

TEST_F(SceneCacheTest, PictureTextBlocksAndPageFieldsRoundTrip) {
  // A scene decoded from bytes holds its picture; text blocks and page fields set as a read page's would be.
  const std::vector<std::uint8_t> bytes = read_bytes(kImages + "fruits.jpg");
  ImageScene is = build_image_scene_from_bytes(bytes, "fruits.jpg", s_);
  ASSERT_FALSE(is.picture.empty());
  is.page = 3;
  is.pages = 12;
  is.document_title = "Früchte — ein Stillleben";
  is.render_dpi = 150.25;
  is.worker_ms = 41.5;
  is.worker_max_rss_kb = 81234;
  is.ocr = {true, "a page of text", 17, 0.8125, 2345.5, 65432};
  is.text_words_masked = 17;
  is.text_blocks.push_back({0, {-0.01, 0.02}, {0.03, 0.0251}, "Apples and pears\nand a lemon", "ocr", 0.8125});
  is.text_blocks.push_back({1, {0.1 / 3, -0.04}, {0.05, -0.039}, "", "pdf", 1.0});
  SceneCache cache(dir_);
  const std::string key = SceneCache::key(bytes, s_);
  ASSERT_TRUE(cache.store(key, is));
  const std::optional<ImageScene> back = cache.load(key, s_);
  ASSERT_TRUE(back);
  expect_same(is, *back);
}

TEST_F(SceneCacheTest, KeyFollowsTheBytesAndTheSettingsThatShapeAScene) {
  const std::vector<std::uint8_t> bytes = read_bytes(kImages + "horse.png");
  const std::string k = SceneCache::key(bytes, s_);
  EXPECT_EQ(k.size(), 64u);
  EXPECT_EQ(k.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(k, SceneCache::key(bytes, config::Settings{}));
  std::vector<std::uint8_t> other = bytes;
  other[other.size() / 2] ^= 1;
  EXPECT_NE(k, SceneCache::key(other, s_));
  EXPECT_NE(k, SceneCache::key(std::span(bytes).first(bytes.size() - 1), s_));

  const std::vector<const config::FieldDescriptor*> shaping = scene_shaping_fields();
  auto shapes = [&](std::string_view table, std::string_view key) {
    return std::any_of(shaping.begin(), shaping.end(),
                       [&](const auto* d) { return d->table == table && d->key == key; });
  };
  EXPECT_TRUE(shapes("vision", "max_shapes"));
  EXPECT_TRUE(shapes("vision", "ocr"));
  EXPECT_TRUE(shapes("workspace", "width_m"));
  EXPECT_TRUE(shapes("workspace", "height_m"));
  EXPECT_TRUE(shapes("haptics", "max_levels"));
  EXPECT_FALSE(shapes("haptics", "stiffness_n_per_m"));
  EXPECT_FALSE(shapes("kiosk", "timeout_s"));
  EXPECT_FALSE(shapes("kiosk", "scene_cache"));

  // Every field changed alone: the key changes exactly when the field shapes a scene.
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    config::Settings changed;
    std::visit(
        [&d](auto* p) {
          using T = std::remove_pointer_t<decltype(p)>;
          if constexpr (std::is_same_v<T, std::string>) {
            const auto other_choice =
                std::find_if(d.choices.begin(), d.choices.end(), [p](std::string_view c) { return c != *p; });
            *p = other_choice != d.choices.end() ? std::string(*other_choice) : *p + "x";
          } else {
            const T lo = static_cast<T>(d.min), hi = static_cast<T>(d.max);
            *p = *p != lo ? lo : hi;
          }
        },
        d.ref(changed));
    const bool is_shaping = shapes(d.table, d.key);
    const std::string name = std::string(d.table) + "." + std::string(d.key);
    if (is_shaping)
      EXPECT_NE(SceneCache::key(bytes, changed), k) << name << " shapes a scene: its change must change the key";
    else
      EXPECT_EQ(SceneCache::key(bytes, changed), k) << name << " does not shape a scene: its change must keep the key";
  }
}

/// The entry file of `key` in `cache`, corrupted in one way; load must refuse it and remove it.
class Corruption : public SceneCacheTest {
 protected:
  void expect_refused(const std::string& what, const std::function<void(const fs::path&)>& corrupt) {
    SCOPED_TRACE(what);
    SceneCache cache(dir_);
    const std::string key = key_of("");
    ASSERT_TRUE(cache.store(key, horse()));
    const fs::path path = cache.entry_path(key);
    corrupt(path);
    EXPECT_FALSE(cache.load(key, s_));
    EXPECT_FALSE(fs::exists(path)) << "a bad entry is removed";
    EXPECT_FALSE(cache.load(key, s_));
    ASSERT_TRUE(cache.store(key, horse())) << "a store after a bad entry works";
    EXPECT_TRUE(cache.load(key, s_));
  }
  /// A header and checksum made for `payload` as the cache makes them, with format `version`.
  static std::vector<std::uint8_t> framed(const std::vector<std::uint8_t>& payload, std::uint32_t version) {
    std::vector<std::uint8_t> out = {'H', 'K', 'S', 'C', 'E', 'N', 'E', '\0'};
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(version >> (8 * i)));
    for (int i = 0; i < 8; ++i)
      out.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(payload.size()) >> (8 * i)));
    crypto_generichash_state st;
    crypto_generichash_init(&st, nullptr, 0, 32);
    crypto_generichash_update(&st, out.data(), out.size());
    crypto_generichash_update(&st, payload.data(), payload.size());
    std::array<std::uint8_t, 32> sum{};
    crypto_generichash_final(&st, sum.data(), sum.size());
    out.insert(out.end(), sum.begin(), sum.end());
    out.insert(out.end(), payload.begin(), payload.end());
    return out;
  }
};

TEST_F(Corruption, BadEntriesAreRefusedRemovedAndReplaced) {
  expect_refused("one byte flipped in the middle", [](const fs::path& p) {
    std::vector<std::uint8_t> b = read_bytes(p);
    b[b.size() / 2] ^= 0x20;
    write_bytes(p, b);
  });
  expect_refused("truncated to half", [](const fs::path& p) { fs::resize_file(p, fs::file_size(p) / 2); });
  expect_refused("empty", [](const fs::path& p) { fs::resize_file(p, 0); });
  expect_refused("random garbage", [](const fs::path& p) {
    std::mt19937 rng(7);
    std::vector<std::uint8_t> b(5000);
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    write_bytes(p, b);
  });
  expect_refused("a valid entry of another format version", [](const fs::path& p) {
    const std::vector<std::uint8_t> b = read_bytes(p);
    write_bytes(p, framed(std::vector<std::uint8_t>(b.begin() + 52, b.end()), kSceneCacheFormat + 1));
  });
  expect_refused("the entry of another key under this name", [this](const fs::path& p) {
    SceneCache other(dir_);
    const std::string k2 = key_of("another");
    ASSERT_TRUE(other.store(k2, horse()));
    fs::rename(other.entry_path(k2), p);
  });
  expect_refused("a checksummed CBOR array claiming 2^64 - 1 items", [](const fs::path& p) {
    write_bytes(p, framed({0x9B, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x00}, kSceneCacheFormat));
  });
  expect_refused("a checksummed CBOR byte string claiming 2^62 bytes", [](const fs::path& p) {
    write_bytes(p, framed({0xA1, 0x61, 'k', 0x5B, 0x40, 0, 0, 0, 0, 0, 0, 0, 1, 2, 3}, kSceneCacheFormat));
  });
  expect_refused("checksummed CBOR nested 100 deep", [](const fs::path& p) {
    write_bytes(p, framed(std::vector<std::uint8_t>(100, 0x81), kSceneCacheFormat));
  });
  expect_refused("a checksummed map that is not a scene", [](const fs::path& p) {
    write_bytes(p, framed({0xA1, 0x63, 'k', 'e', 'y', 0x01}, kSceneCacheFormat));
  });
}

TEST_F(SceneCacheTest, ReadOnlyFolderCostsTheStoreOnly) {
  // The stores into the mode-0555 folder run as the kiosk's service user would: root's override of file
  // modes (CAP_DAC_OVERRIDE) dropped, so they are refused under root (CI) too.
  SceneCache cache(dir_);
  const std::string key = key_of("");
  ASSERT_TRUE(cache.store(key, horse()));
  fs::permissions(dir_, fs::perms(0555), fs::perm_options::replace);
  bool stored = true;
  EXPECT_NO_THROW(stored = hk::test::without_file_override([&] { return cache.store(key_of("second"), horse()); }));
  EXPECT_FALSE(stored);
  EXPECT_FALSE(hk::test::without_file_override([&] { return cache.store(key_of("third"), horse()); }))
      << "and again (logged once)";
  EXPECT_TRUE(hk::test::without_file_override([&] { return cache.load(key, s_); }))
      << "entries already there still load";
  EXPECT_EQ(files_in(dir_), std::vector<std::string>{key + ".scene"});
}

TEST_F(SceneCacheTest, FolderPathIsAFile) {
  const fs::path file = root_ / "not_a_folder";
  write_bytes(file, {1, 2, 3});
  SceneCache cache((file / "scenes").string());
  bool stored = true;
  EXPECT_NO_THROW(stored = cache.store(key_of(""), horse()));
  EXPECT_FALSE(stored);
  EXPECT_FALSE(cache.load(key_of(""), s_));
  EXPECT_EQ(read_bytes(file), (std::vector<std::uint8_t>{1, 2, 3}));
}

TEST_F(SceneCacheTest, DiskFullCostsTheStoreOnly) {
  // A file size limit (RLIMIT_FSIZE, which binds root too) makes the write fail as a full disk does.
  SceneCache cache(dir_);
  const std::string key = key_of("");
  ASSERT_TRUE(cache.store(key, horse()));
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 100;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  bool stored = true;
  EXPECT_NO_THROW(stored = cache.store(key_of("second"), horse()));
  EXPECT_FALSE(stored);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &old), 0);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(files_in(dir_), std::vector<std::string>{key + ".scene"}) << "the partial temporary file is removed";
  EXPECT_TRUE(cache.load(key, s_));
  EXPECT_TRUE(cache.store(key_of("second"), horse())) << "room again: stores work again";
}

TEST_F(SceneCacheTest, SizeCapRemovesTheLeastRecentlyUsedEntry) {
  const std::string a = key_of("a"), b = key_of("b"), c = key_of("c");
  std::uintmax_t entry = 0;
  {
    SceneCache probe(dir_);
    ASSERT_TRUE(probe.store(a, horse()));
    entry = fs::file_size(probe.entry_path(a));
  }
  SceneCache cache(dir_, static_cast<std::int64_t>(entry * 5 / 2));  // room for two entries
  ASSERT_TRUE(cache.store(b, horse()));
  EXPECT_EQ(files_in(dir_).size(), 2u);
  // a stored long ago, b after it; then a is used: b is now the least recently used.
  const auto now = fs::file_time_type::clock::now();
  fs::last_write_time(cache.entry_path(a), now - std::chrono::seconds(200));
  fs::last_write_time(cache.entry_path(b), now - std::chrono::seconds(100));
  ASSERT_TRUE(cache.load(a, s_));
  ASSERT_TRUE(cache.store(c, horse()));
  EXPECT_TRUE(fs::exists(cache.entry_path(a)));
  EXPECT_FALSE(fs::exists(cache.entry_path(b)));
  EXPECT_TRUE(fs::exists(cache.entry_path(c)));
  // Without the load the oldest goes.
  fs::last_write_time(cache.entry_path(a), now - std::chrono::seconds(300));
  ASSERT_TRUE(cache.store(b, horse()));
  EXPECT_FALSE(fs::exists(cache.entry_path(a)));
  EXPECT_EQ(files_in(dir_), (std::vector<std::string>{std::min(b, c) + ".scene", std::max(b, c) + ".scene"}));
  // An entry larger than the whole cache is not stored.
  SceneCache tiny(dir_, static_cast<std::int64_t>(entry / 2));
  EXPECT_FALSE(tiny.store(a, horse()));
}

// A picture seen before is found by its stamp (path and stat) without reading its bytes; what the file
// says of itself comes back with the scene; any change to the file, or to a setting that shapes scenes,
// misses; a ref that holds no key, or whose entry was evicted, is removed.
TEST_F(SceneCacheTest, AFileSeenBeforeIsFoundByItsStampWithTheFilesOwnNotes) {
  const fs::path pic = root_ / "pic.png";
  fs::copy_file(kImages + "horse.png", pic);
  SceneCache cache(dir_);
  const std::optional<FileStamp> stamp = SceneCache::stamp(pic.string());
  ASSERT_TRUE(stamp);
  EXPECT_EQ(stamp->size_bytes, fs::file_size(pic));
  EXPECT_FALSE(cache.known_key(*stamp, s_)) << "nothing remembered yet";
  EXPECT_FALSE(SceneCache::stamp((root_ / "missing.png").string()));

  ImageScene is = copy_of(horse(), s_);
  is.file_notes.title = "A horse";
  is.file_notes.description = "Drawn from the side.";
  const std::string key = SceneCache::key(read_bytes(pic), s_);
  ASSERT_TRUE(cache.store(key, is));
  cache.remember_key(*stamp, s_, key);
  const std::vector<std::string> files = files_in(dir_);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(std::count_if(files.begin(), files.end(), [](const std::string& f) { return f.ends_with(".ref"); }), 1);

  const std::optional<std::string> known = cache.known_key(*SceneCache::stamp(pic.string()), s_);
  ASSERT_TRUE(known);
  EXPECT_EQ(*known, key);
  const std::optional<ImageScene> back = cache.load(*known, s_);
  ASSERT_TRUE(back);
  expect_same(is, *back);

  config::Settings gains = s_;
  gains.haptics.stiffness_n_per_m *= 2;  // does not shape a scene
  EXPECT_EQ(cache.known_key(*stamp, gains), key);
  config::Settings shaping = s_;
  shaping.vision.max_image_side_px += 100;
  EXPECT_FALSE(cache.known_key(*stamp, shaping)) << "a setting that shapes scenes is part of the ref";

  {  // a byte appended: another size
    std::ofstream(pic, std::ios::app | std::ios::binary) << 'x';
  }
  EXPECT_FALSE(cache.known_key(*SceneCache::stamp(pic.string()), s_));
  // Another file renamed over it, byte for byte the old one: another inode.
  fs::copy_file(kImages + "horse.png", root_ / "other.png");
  fs::rename(root_ / "other.png", pic);
  EXPECT_FALSE(cache.known_key(*SceneCache::stamp(pic.string()), s_));

  // A ref that holds no key is removed; then nothing is known.
  fs::path ref;
  for (const std::string& f : files_in(dir_))
    if (f.ends_with(".ref")) ref = fs::path(dir_) / f;
  write_bytes(ref, {'n', 'o', '\n'});
  EXPECT_FALSE(cache.known_key(*stamp, s_));
  EXPECT_FALSE(fs::exists(ref));

  // A ref whose entry is gone is removed when entries are next evicted.
  cache.remember_key(*stamp, s_, key);
  ASSERT_TRUE(fs::exists(ref));
  fs::remove(cache.entry_path(key));
  ASSERT_TRUE(cache.store(key_of("another"), horse()));
  EXPECT_FALSE(fs::exists(ref));
  cache.remember_key(*stamp, s_, "not a key");
  EXPECT_FALSE(fs::exists(ref)) << "only keys are remembered";
}

TEST_F(SceneCacheTest, OffFindsNothingAndWritesNothing) {
  SceneCache cache("");
  const std::vector<std::string> before = files_in(root_.string());
  EXPECT_EQ(cache.dir(), "");
  EXPECT_EQ(cache.entry_path(key_of("")), "");
  EXPECT_FALSE(cache.store(key_of(""), horse()));
  EXPECT_FALSE(cache.load(key_of(""), s_));
  EXPECT_EQ(files_in(root_.string()), before);
}

TEST_F(SceneCacheTest, OnlyCompleteScenesWithAKeyAreStored) {
  SceneCache cache(dir_);
  ImageScene pending = copy_of(horse(), s_);
  pending.text_pending = true;
  EXPECT_FALSE(cache.store(key_of(""), pending));
  ImageScene no_trees = copy_of(horse(), s_);
  no_trees.scene.reset();
  EXPECT_FALSE(cache.store(key_of(""), no_trees));
  EXPECT_FALSE(cache.store("../escape", horse()));
  EXPECT_FALSE(cache.load("../escape", s_));
  EXPECT_TRUE(files_in(dir_).empty());
}

/// Sets an environment variable for the scope, restoring its old value (or its absence) after.
class EnvVar {
 public:
  EnvVar(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value != nullptr)
      ::setenv(name, value, 1);
    else
      ::unsetenv(name);
  }
  ~EnvVar() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }
  EnvVar(const EnvVar&) = delete;
  EnvVar& operator=(const EnvVar&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(SceneCacheDir, OffAbsoluteAndAuto) {
  config::Settings s;
  s.kiosk.scene_cache = "off";
  EXPECT_EQ(scene_cache_dir(s), "");
  s.kiosk.scene_cache = "/srv/kiosk/scenes";
  EXPECT_EQ(scene_cache_dir(s), "/srv/kiosk/scenes");
  s.kiosk.scene_cache = "auto";
  {
    EnvVar cache("CACHE_DIRECTORY", "/var/cache/haptic-kiosk:/var/cache/other");
    EnvVar xdg("XDG_CACHE_HOME", "/home/k/.xdg");
    EnvVar home("HOME", "/home/k");
    EXPECT_EQ(scene_cache_dir(s), "/var/cache/haptic-kiosk/scenes");
  }
  {
    EnvVar cache("CACHE_DIRECTORY", nullptr);
    EnvVar xdg("XDG_CACHE_HOME", "/home/k/.xdg");
    EnvVar home("HOME", "/home/k");
    EXPECT_EQ(scene_cache_dir(s), "/home/k/.xdg/haptic-kiosk/scenes");
  }
  {
    EnvVar cache("CACHE_DIRECTORY", nullptr);
    EnvVar xdg("XDG_CACHE_HOME", "relative/is/ignored");
    EnvVar home("HOME", "/home/k");
    EXPECT_EQ(scene_cache_dir(s), "/home/k/.cache/haptic-kiosk/scenes");
  }
  {
    EnvVar cache("CACHE_DIRECTORY", nullptr);
    EnvVar xdg("XDG_CACHE_HOME", nullptr);
    EnvVar home("HOME", nullptr);
    EXPECT_EQ(scene_cache_dir(s), "");
  }
}

}  // namespace
}  // namespace hk::app
