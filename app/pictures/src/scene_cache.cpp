// Built scenes on disk (scene_cache.hpp).
#include "pictures/scene_cache.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string_view>
#include <utility>

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#ifndef HK_PROGRAM_VERSION
#error "HK_PROGRAM_VERSION (the project's version) must be defined by the build"
#endif

namespace hk::app {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr std::array<std::uint8_t, 8> kMagic = {'H', 'K', 'S', 'C', 'E', 'N', 'E', '\0'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 8;                   // magic, format, payload size
constexpr std::size_t kChecksumBytes = crypto_generichash_BYTES;  // 32
constexpr std::size_t kPrefixBytes = kHeaderBytes + kChecksumBytes;
constexpr std::string_view kSuffix = ".scene";
constexpr std::string_view kRefSuffix = ".ref";
constexpr std::size_t kRefBytes = 2 * crypto_generichash_BYTES + 1;  // a key and a line feed
constexpr std::string_view kTempPrefix = ".tmp-";
/// CBOR values a payload may hold: far above a scene's (a few hundred per curve at most, the points being
/// byte strings), far below what would make the parsed tree large (about 100 bytes a value).
constexpr std::size_t kMaxCborValues = 1u << 20;
constexpr std::size_t kMaxCborDepth = 8;
/// Largest picture an entry may hold [px]: the decoded picture is allocated from the JPEG's own header.
constexpr std::int64_t kMaxPicturePixels = 100'000'000;
/// A temporary file this old is a crashed writer's [s].
constexpr auto kStaleTemp = std::chrono::hours(1);

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void put_u64(std::vector<std::uint8_t>& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
std::uint64_t get_le(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}

/// Doubles as little-endian IEEE-754 bytes.
json::binary_t to_binary(const double* v, std::size_t n) {
  std::vector<std::uint8_t> out;
  out.reserve(8 * n);
  for (std::size_t i = 0; i < n; ++i) put_u64(out, std::bit_cast<std::uint64_t>(v[i]));
  return json::binary_t(std::move(out));
}

/// Thrown while reading a payload: what is wrong with it (one phrase).
struct BadEntry {
  std::string why;
};

/// The doubles of a CBOR byte string of little-endian doubles.
std::vector<double> from_binary(const json& j, const char* name) {
  if (!j.is_binary()) throw BadEntry{std::string(name) + " is not a byte string"};
  const std::vector<std::uint8_t>& b = j.get_binary();
  if (b.size() % 8 != 0) throw BadEntry{std::string(name) + " is not a whole number of doubles"};
  std::vector<double> out(b.size() / 8);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = std::bit_cast<double>(get_le(b.data() + 8 * i, 8));
  return out;
}

/// Counts the values of a CBOR document and its nesting, refusing it (false) past kMaxCborValues or
/// kMaxCborDepth, before it is parsed into a tree.
struct CborBudget : json::json_sax_t {
  std::size_t values = 0, depth = 0;
  bool value() { return ++values <= kMaxCborValues; }
  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override { return value() && ++depth <= kMaxCborDepth; }
  bool key(string_t&) override { return value(); }
  bool end_object() override {
    --depth;
    return true;
  }
  bool start_array(std::size_t) override { return value() && ++depth <= kMaxCborDepth; }
  bool end_array() override {
    --depth;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }
};

/// Width and height of a baseline/progressive JPEG from its SOF marker, without decoding it; false when
/// there is none before the data.
bool jpeg_size(const std::vector<std::uint8_t>& b, int& width, int& height) {
  if (b.size() < 4 || b[0] != 0xFF || b[1] != 0xD8) return false;
  std::size_t i = 2;
  while (i + 4 <= b.size()) {
    if (b[i] != 0xFF) return false;
    const std::uint8_t m = b[i + 1];
    if (m == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    const std::size_t len = (static_cast<std::size_t>(b[i + 2]) << 8) | b[i + 3];
    if (len < 2) return false;
    const bool sof = m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC;
    if (sof) {
      if (i + 9 > b.size()) return false;
      height = (b[i + 5] << 8) | b[i + 6];
      width = (b[i + 7] << 8) | b[i + 8];
      return true;
    }
    if (m == 0xDA || m == 0xD9) return false;  // scan data or end without a frame header
    i += 2 + len;
  }
  return false;
}

bool is_key(const std::string& k) {
  return k.size() == 2 * crypto_generichash_BYTES &&
         std::all_of(k.begin(), k.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

std::string errno_text(int e) { return std::strerror(e); }

/// The payload of an entry: every kept field of `is`. What is not kept: `scene` (rebuilt from the
/// polylines on load, about 1 ms, and not a stable format), `with_text` (a function; only complete
/// scenes are stored, so text_pending is always false) and the picture's exact pixels (JPEG quality 90:
/// the screen shows it, nothing measures it).
json to_payload(const std::string& key, const ImageScene& is) {
  json j;
  j["key"] = key;
  j["image_path"] = is.image_path;
  j["page"] = is.page;
  j["pages"] = is.pages;
  j["document_title"] = is.document_title;
  if (!is.picture.empty()) {
    std::vector<std::uint8_t> jpeg;
    if (!cv::imencode(".jpg", is.picture, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}))
      throw BadEntry{"the picture could not be encoded"};
    j["picture"] = {{"cols", is.picture.cols}, {"rows", is.picture.rows}, {"jpeg", json::binary_t(std::move(jpeg))}};
  }
  json blocks = json::array();
  for (const TextBlockM& b : is.text_blocks) {
    blocks.push_back({{"id", b.id},
                      {"box_m", {b.lo_m.x, b.lo_m.y, b.hi_m.x, b.hi_m.y}},
                      {"text", b.text},
                      {"source", b.source},
                      {"confidence", b.confidence}});
  }
  j["text_blocks"] = std::move(blocks);
  j["ocr"] = {{"ran", is.ocr.ran},     {"why", is.ocr.why},
              {"words", is.ocr.words}, {"mean_confidence", is.ocr.mean_confidence},
              {"ms", is.ocr.ms},       {"worker_max_rss_kb", is.ocr.worker_max_rss_kb}};
  j["text_likely"] = is.text_likely;
  j["text_words_masked"] = is.text_words_masked;
  j["file_notes"] = {{"title", is.file_notes.title}, {"description", is.file_notes.description}};
  j["render_dpi"] = is.render_dpi;
  j["worker_ms"] = is.worker_ms;
  j["worker_max_rss_kb"] = is.worker_max_rss_kb;
  j["width_px"] = is.width_px;
  j["height_px"] = is.height_px;
  j["file_px"] = {is.file_width_px, is.file_height_px, is.decode_scale};
  j["px_to_m"] = {is.px_to_m.scale_m_per_px, is.px_to_m.offset_x_m, is.px_to_m.offset_y_m};
  j["counts"] = {{"chains_texture", is.chains_texture},
                 {"chains_found", is.chains_found},
                 {"thin_line_pairs_merged", is.thin_line_pairs_merged},
                 {"chains_after_thin_lines", is.chains_after_thin_lines},
                 {"gaps_closed", is.gaps_closed},
                 {"chains_closed_by_gaps", is.chains_closed_by_gaps},
                 {"chains_after_gaps", is.chains_after_gaps},
                 {"chains_too_short", is.chains_too_short},
                 {"chains_along_border", is.chains_along_border},
                 {"chains_over_max_shapes", is.chains_over_max_shapes},
                 {"chains_over_budget", is.chains_over_budget},
                 {"segments_before_budget", is.segments_before_budget},
                 {"segments_after_budget", is.segments_after_budget}};
  j["canny"] = {is.canny_low, is.canny_high};
  j["detector"] = vision::detector_name(is.detector);
  j["tones"] = {{"two_tone", is.tones.two_tone},     {"threshold", is.tones.threshold},
                {"dark_mean", is.tones.dark_mean},   {"light_mean", is.tones.light_mean},
                {"near_share", is.tones.near_share}, {"ink_width_px", is.tones.ink_width_px}};
  j["line_drawing"] = is.line_drawing;
  json curves = json::array();
  for (const Polyline& p : is.polylines) {
    static_assert(sizeof(Vec2) == 2 * sizeof(double), "Vec2 is two doubles");
    std::vector<double> xy;
    xy.reserve(2 * p.points_m.size());
    for (const Vec2& q : p.points_m) {
      xy.push_back(q.x);
      xy.push_back(q.y);
    }
    curves.push_back({{"closed", p.closed}, {"points_m", to_binary(xy.data(), xy.size())}});
  }
  j["polylines"] = std::move(curves);
  j["strength"] = to_binary(is.strength.data(), is.strength.size());
  const BuildTimes& t = is.times;
  j["times_ms"] = {t.load_ms, t.edges_ms, t.linking_ms, t.thin_lines_ms, t.gaps_ms, t.multires_ms, t.tree_ms};
  return j;
}

/// The screen's picture of a payload's "picture" map: a JPEG whose header agrees with the size given.
cv::Mat picture_from(const json& p) {
  const int cols = p.at("cols").get<int>(), rows = p.at("rows").get<int>();
  const json& jpeg = p.at("jpeg");
  if (!jpeg.is_binary()) throw BadEntry{"the picture is not a byte string"};
  int w = 0, h = 0;
  if (!jpeg_size(jpeg.get_binary(), w, h) || w != cols || h != rows || cols <= 0 || rows <= 0 ||
      static_cast<std::int64_t>(cols) * rows > kMaxPicturePixels)
    throw BadEntry{"the picture's JPEG header disagrees with its size"};
  cv::Mat picture = cv::imdecode(jpeg.get_binary(), cv::IMREAD_COLOR);
  if (picture.cols != cols || picture.rows != rows) throw BadEntry{"the picture does not decode"};
  return picture;
}

/// A payload's text: its blocks, what OCR did, and the file's own notes.
void text_from(const json& j, ImageScene& is) {
  for (const json& b : j.at("text_blocks")) {
    TextBlockM t;
    t.id = b.at("id").get<int>();
    const json& box = b.at("box_m");
    if (!box.is_array() || box.size() != 4) throw BadEntry{"a text block's box is not 4 numbers"};
    t.lo_m = {box[0].get<double>(), box[1].get<double>()};
    t.hi_m = {box[2].get<double>(), box[3].get<double>()};
    t.text = b.at("text").get<std::string>();
    t.source = b.at("source").get<std::string>();
    t.confidence = b.at("confidence").get<double>();
    is.text_blocks.push_back(std::move(t));
  }
  const json& o = j.at("ocr");
  is.ocr.ran = o.at("ran").get<bool>();
  is.ocr.why = o.at("why").get<std::string>();
  is.ocr.words = o.at("words").get<int>();
  is.ocr.mean_confidence = o.at("mean_confidence").get<double>();
  is.ocr.ms = o.at("ms").get<double>();
  is.ocr.worker_max_rss_kb = o.at("worker_max_rss_kb").get<long>();
  is.text_likely = j.at("text_likely").get<bool>();
  is.text_words_masked = j.at("text_words_masked").get<std::size_t>();
  const json& n = j.at("file_notes");
  is.file_notes.title = n.at("title").get<std::string>();
  is.file_notes.description = n.at("description").get<std::string>();
}

/// A payload's sizes: the rendered page's, the picture's, the file's, and the pixel map.
void geometry_from(const json& j, ImageScene& is) {
  is.render_dpi = j.at("render_dpi").get<double>();
  is.worker_ms = j.at("worker_ms").get<double>();
  is.worker_max_rss_kb = j.at("worker_max_rss_kb").get<long>();
  is.width_px = j.at("width_px").get<int>();
  is.height_px = j.at("height_px").get<int>();
  const json& f = j.at("file_px");
  if (!f.is_array() || f.size() != 3) throw BadEntry{"file_px is not 3 numbers"};
  is.file_width_px = f[0].get<int>();
  is.file_height_px = f[1].get<int>();
  is.decode_scale = f[2].get<int>();
  const json& m = j.at("px_to_m");
  if (!m.is_array() || m.size() != 3) throw BadEntry{"px_to_m is not 3 numbers"};
  is.px_to_m = {m[0].get<double>(), m[1].get<double>(), m[2].get<double>()};
}

/// A payload's counts of what the build found and dropped.
void counts_from(const json& c, ImageScene& is) {
  is.chains_texture = c.at("chains_texture").get<std::size_t>();
  is.chains_found = c.at("chains_found").get<std::size_t>();
  is.thin_line_pairs_merged = c.at("thin_line_pairs_merged").get<std::size_t>();
  is.chains_after_thin_lines = c.at("chains_after_thin_lines").get<std::size_t>();
  is.gaps_closed = c.at("gaps_closed").get<std::size_t>();
  is.chains_closed_by_gaps = c.at("chains_closed_by_gaps").get<std::size_t>();
  is.chains_after_gaps = c.at("chains_after_gaps").get<std::size_t>();
  is.chains_too_short = c.at("chains_too_short").get<std::size_t>();
  is.chains_along_border = c.at("chains_along_border").get<std::size_t>();
  is.chains_over_max_shapes = c.at("chains_over_max_shapes").get<std::size_t>();
  is.chains_over_budget = c.at("chains_over_budget").get<std::size_t>();
  is.segments_before_budget = c.at("segments_before_budget").get<std::size_t>();
  is.segments_after_budget = c.at("segments_after_budget").get<std::size_t>();
}

/// A payload's edge detection: thresholds, detector, the picture's tones.
void detection_from(const json& j, ImageScene& is) {
  const json& canny = j.at("canny");
  if (!canny.is_array() || canny.size() != 2) throw BadEntry{"canny is not 2 numbers"};
  is.canny_low = canny[0].get<double>();
  is.canny_high = canny[1].get<double>();
  try {
    is.detector = vision::detector_from_name(j.at("detector").get<std::string>());
  } catch (const hk::Error&) {
    throw BadEntry{"it names an unknown detector"};
  }
  const json& tn = j.at("tones");
  is.tones.two_tone = tn.at("two_tone").get<bool>();
  is.tones.threshold = tn.at("threshold").get<double>();
  is.tones.dark_mean = tn.at("dark_mean").get<double>();
  is.tones.light_mean = tn.at("light_mean").get<double>();
  is.tones.near_share = tn.at("near_share").get<double>();
  is.tones.ink_width_px = tn.at("ink_width_px").get<double>();
  is.line_drawing = j.at("line_drawing").get<bool>();
}

/// A payload's curves and their strengths.
void curves_from(const json& j, ImageScene& is) {
  for (const json& p : j.at("polylines")) {
    const std::vector<double> xy = from_binary(p.at("points_m"), "a polyline's points");
    if (xy.size() % 2 != 0) throw BadEntry{"a polyline has an odd number of coordinates"};
    Polyline pl;
    pl.closed = p.at("closed").get<bool>();
    pl.points_m.reserve(xy.size() / 2);
    for (std::size_t i = 0; i < xy.size(); i += 2) pl.points_m.push_back({xy[i], xy[i + 1]});
    is.polylines.push_back(std::move(pl));
  }
  is.strength = from_binary(j.at("strength"), "strength");
  if (is.strength.size() != is.polylines.size()) throw BadEntry{"strength and polylines differ in count"};
}

/// The ImageScene of a payload (its Scene not built). Throws BadEntry or json::exception on anything but
/// what to_payload writes.
ImageScene from_payload(const json& j, const std::string& key) {
  if (!j.is_object()) throw BadEntry{"the payload is not a map"};
  if (j.at("key").get<std::string>() != key) throw BadEntry{"holds the scene of another key"};
  ImageScene is;
  is.image_path = j.at("image_path").get<std::string>();
  is.page = j.at("page").get<int>();
  is.pages = j.at("pages").get<int>();
  is.document_title = j.at("document_title").get<std::string>();
  if (j.contains("picture")) is.picture = picture_from(j.at("picture"));
  text_from(j, is);
  geometry_from(j, is);
  counts_from(j.at("counts"), is);
  detection_from(j, is);
  curves_from(j, is);
  const json& t = j.at("times_ms");
  if (!t.is_array() || t.size() != 7) throw BadEntry{"times_ms is not 7 numbers"};
  is.times = {t[0].get<double>(), t[1].get<double>(), t[2].get<double>(), t[3].get<double>(),
              t[4].get<double>(), t[5].get<double>(), t[6].get<double>()};
  return is;
}

/// The checksum of an entry's header (bytes 0..19) and payload.
std::array<std::uint8_t, kChecksumBytes> checksum(const std::uint8_t* header, const std::uint8_t* payload,
                                                  std::size_t payload_size) {
  crypto_generichash_state st;
  crypto_generichash_init(&st, nullptr, 0, kChecksumBytes);
  crypto_generichash_update(&st, header, kHeaderBytes);
  crypto_generichash_update(&st, payload, payload_size);
  std::array<std::uint8_t, kChecksumBytes> out{};
  crypto_generichash_final(&st, out.data(), out.size());
  return out;
}

/// The whole entry file of a payload: header, checksum, payload.
std::vector<std::uint8_t> entry_bytes(const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> out;
  out.reserve(kPrefixBytes + payload.size());
  out.insert(out.end(), kMagic.begin(), kMagic.end());
  put_u32(out, kSceneCacheFormat);
  put_u64(out, payload.size());
  const auto sum = checksum(out.data(), payload.data(), payload.size());
  out.insert(out.end(), sum.begin(), sum.end());
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

/// Reads the whole file `fd` of `size` bytes; false on a read error or a short read.
bool read_all(int fd, std::uint8_t* out, std::size_t size) {
  std::size_t got = 0;
  while (got < size) {
    const ssize_t n = ::read(fd, out + got, size - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    got += static_cast<std::size_t>(n);
  }
  return true;
}

/// Writes all of `data` to `fd`; false with errno set on failure.
bool write_all(int fd, const std::uint8_t* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return false;
    if (n == 0) {
      errno = ENOSPC;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

/// Creates `dir` and every missing parent with mode 0700; false with errno set when it could not (a
/// component that exists but is no folder: ENOTDIR).
bool make_dirs(const std::string& dir) {
  std::string prefix;
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    pos = dir.find('/', pos + 1);
    prefix = dir.substr(0, pos);
    if (prefix.empty()) continue;
    if (::mkdir(prefix.c_str(), 0700) == 0) continue;
    if (errno != EEXIST) return false;
    struct stat st {};
    if (::stat(prefix.c_str(), &st) != 0) return false;
    if (!S_ISDIR(st.st_mode)) {
      errno = ENOTDIR;
      return false;
    }
  }
  return true;
}

/// Hash input helpers: lengths and numbers as fixed-size little-endian words, so no two inputs hash alike.
void hash_u64(crypto_generichash_state& st, std::uint64_t v) {
  std::uint8_t b[8];
  for (int i = 0; i < 8; ++i) b[i] = static_cast<std::uint8_t>(v >> (8 * i));
  crypto_generichash_update(&st, b, sizeof b);
}
void hash_text(crypto_generichash_state& st, std::string_view s) {
  hash_u64(st, s.size());
  crypto_generichash_update(&st, reinterpret_cast<const unsigned char*>(s.data()), s.size());
}

/// Starts a BLAKE2b-256 over `domain`, the entry format, the program version and every
/// scene_shaping_fields() setting ("table.key" and its exact value: doubles by their bits).
void begin_settings_hash(crypto_generichash_state& st, std::string_view domain, const config::Settings& s) {
  [[maybe_unused]] const int ready = sodium_init();  // picks the fastest BLAKE2b; the portable one serves when it fails
  crypto_generichash_init(&st, nullptr, 0, crypto_generichash_BYTES);
  hash_text(st, domain);
  hash_u64(st, kSceneCacheFormat);
  hash_text(st, HK_PROGRAM_VERSION);
  for (const config::FieldDescriptor* d : scene_shaping_fields()) {
    hash_text(st, std::string(d->table) + "." + std::string(d->key));
    std::visit(
        [&st](const auto* p) {
          using T = std::remove_cv_t<std::remove_pointer_t<decltype(p)>>;
          if constexpr (std::is_same_v<T, double>) {
            hash_text(st, "d");
            hash_u64(st, std::bit_cast<std::uint64_t>(*p));
          } else if constexpr (std::is_same_v<T, std::string>) {
            hash_text(st, "s");
            hash_text(st, *p);
          } else {
            hash_text(st, "i");
            hash_u64(st, static_cast<std::uint64_t>(static_cast<std::int64_t>(*p)));
          }
        },
        d->cref(s));
  }
}

/// The hash as 64 lower-case hex digits.
std::string final_hex(crypto_generichash_state& st) {
  std::array<std::uint8_t, crypto_generichash_BYTES> h{};
  crypto_generichash_final(&st, h.data(), h.size());
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * h.size());
  for (std::uint8_t b : h) {
    out.push_back(kHex[b >> 4]);
    out.push_back(kHex[b & 15]);
  }
  return out;
}

}  // namespace

std::string scene_cache_dir(const config::Settings& s) {
  const std::string& v = s.kiosk.scene_cache;
  if (v == "off") return "";
  if (v != "auto") return v;
  auto absolute = [](const char* name) -> std::string {
    const char* e = std::getenv(name);
    if (e == nullptr || e[0] != '/') return "";
    return e;
  };
  std::string cache = absolute("CACHE_DIRECTORY");
  if (!cache.empty()) {
    cache = cache.substr(0, cache.find(':'));
    return cache + "/scenes";
  }
  const std::string xdg = absolute("XDG_CACHE_HOME");
  if (!xdg.empty()) return xdg + "/haptic-kiosk/scenes";
  const std::string home = absolute("HOME");
  if (!home.empty()) return home + "/.cache/haptic-kiosk/scenes";
  return "";
}

std::vector<const config::FieldDescriptor*> scene_shaping_fields() {
  std::vector<const config::FieldDescriptor*> out;
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    if (d.apply == config::ApplyWhen::scene || d.table == "workspace" ||
        (d.table == "haptics" && d.key == "max_levels"))
      out.push_back(&d);
  }
  return out;
}

SceneCache::SceneCache(std::string dir, std::int64_t max_bytes)
    : dir_(std::move(dir)), max_bytes_(std::max<std::int64_t>(max_bytes, 1)) {
  while (dir_.size() > 1 && dir_.back() == '/') dir_.pop_back();
}

std::string SceneCache::entry_path(const std::string& key) const {
  if (dir_.empty()) return "";
  return dir_ + "/" + key + std::string(kSuffix);
}

std::string SceneCache::key(std::span<const std::uint8_t> file_bytes, const config::Settings& s) {
  crypto_generichash_state st;
  begin_settings_hash(st, "haptic-kiosk scene", s);
  hash_text(st, "file");
  hash_u64(st, file_bytes.size());
  crypto_generichash_update(&st, file_bytes.data(), file_bytes.size());
  return final_hex(st);
}

std::optional<FileStamp> SceneCache::stamp(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  FileStamp f;
  f.path = path;
  f.device = static_cast<std::uint64_t>(st.st_dev);
  f.inode = static_cast<std::uint64_t>(st.st_ino);
  f.size_bytes = static_cast<std::uint64_t>(st.st_size);
  f.mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
  f.ctime_ns = static_cast<std::int64_t>(st.st_ctim.tv_sec) * 1'000'000'000 + st.st_ctim.tv_nsec;
  return f;
}

namespace {

/// The name of the ref file of a stamp under settings (64 hex digits and ".ref").
std::string ref_name(const FileStamp& f, const config::Settings& s) {
  crypto_generichash_state st;
  begin_settings_hash(st, "haptic-kiosk file stamp", s);
  hash_text(st, f.path);
  for (const std::uint64_t v : {f.device, f.inode, f.size_bytes, static_cast<std::uint64_t>(f.mtime_ns),
                                static_cast<std::uint64_t>(f.ctime_ns)})
    hash_u64(st, v);
  return final_hex(st) + std::string(kRefSuffix);
}

}  // namespace

std::optional<std::string> SceneCache::known_key(const FileStamp& stamp, const config::Settings& s) const {
  if (dir_.empty()) return std::nullopt;
  const std::string path = dir_ + "/" + ref_name(stamp, s);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return std::nullopt;
  std::array<char, kRefBytes + 1> buf{};
  const ssize_t n = ::read(fd, buf.data(), buf.size());
  ::close(fd);
  const std::string key(buf.data(), n > 0 ? static_cast<std::size_t>(n) : 0);
  if (key.size() == kRefBytes && key.back() == '\n' && is_key(key.substr(0, kRefBytes - 1)))
    return key.substr(0, kRefBytes - 1);
  ::unlink(path.c_str());
  spdlog::warn("scene cache: ref '{}' does not hold a key; removed", path);
  return std::nullopt;
}

void SceneCache::remember_key(const FileStamp& stamp, const config::Settings& s, const std::string& key) {
  if (dir_.empty() || !is_key(key)) return;
  const std::string text = key + "\n";
  const std::string failed = write_atomically(ref_name(stamp, s), std::vector<std::uint8_t>(text.begin(), text.end()));
  if (!failed.empty())
    warn_once(failed, "in '" + dir_ + "': cannot " + failed + "; pictures are read again to find their scenes");
}

std::string SceneCache::write_atomically(const std::string& name, const std::vector<std::uint8_t>& bytes) const {
  auto failed = [](const std::string& stage, int err) { return stage + ": " + errno_text(err); };
  if (!make_dirs(dir_)) return failed("create the folder", errno);
  std::string temp = dir_ + "/" + std::string(kTempPrefix) + name + "-XXXXXX";
  const int fd = ::mkostemp(temp.data(), O_CLOEXEC);
  if (fd < 0) return failed("create a file", errno);
  const bool written = write_all(fd, bytes.data(), bytes.size()) && ::fsync(fd) == 0;
  const int write_errno = errno;
  const bool closed = ::close(fd) == 0;
  if (!written || !closed) {
    const int err = written ? errno : write_errno;
    ::unlink(temp.c_str());
    return failed("write a file", err);
  }
  if (::rename(temp.c_str(), (dir_ + "/" + name).c_str()) != 0) {
    const int err = errno;
    ::unlink(temp.c_str());
    return failed("rename a file", err);
  }
  const int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {  // the rename itself durable; a failure here costs only that
    ::fsync(dfd);
    ::close(dfd);
  }
  return "";
}

std::optional<ImageScene> SceneCache::load(const std::string& key, const config::Settings& s) const {
  if (dir_.empty() || !is_key(key)) return std::nullopt;
  const std::string path = entry_path(key);
  auto bad = [&path](const std::string& why) -> std::optional<ImageScene> {
    const bool removed = ::unlink(path.c_str()) == 0;
    spdlog::warn("scene cache: entry '{}' {}; {}", path, why,
                 removed ? "removed" : "could not be removed: " + errno_text(errno));
    return std::nullopt;
  };
  try {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) {
      if (errno == ENOENT || errno == ENOTDIR) return std::nullopt;  // no entry, or no folder (store says why)
      if (errno == ELOOP) return bad("is a symbolic link");
      spdlog::warn("scene cache: cannot read entry '{}': {}", path, errno_text(errno));
      return std::nullopt;
    }
    struct Closer {
      int fd;
      ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) return std::nullopt;
    if (!S_ISREG(st.st_mode)) return bad("is not a regular file");
    if (st.st_size < static_cast<off_t>(kPrefixBytes))
      return bad("is too short to be an entry (" + std::to_string(st.st_size) + " bytes)");
    if (st.st_size > kSceneCacheMaxEntryBytes)
      return bad("is larger than an entry may be (" + std::to_string(st.st_size) + " bytes)");
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
    if (!read_all(fd, bytes.data(), bytes.size())) return bad("could not be read whole");
    if (!std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) return bad("is not a scene entry (wrong magic)");
    const auto format = static_cast<std::uint32_t>(get_le(bytes.data() + 8, 4));
    if (format != kSceneCacheFormat)
      return bad("is of format " + std::to_string(format) + ", not " + std::to_string(kSceneCacheFormat) + " (stale)");
    const std::uint64_t payload_size = get_le(bytes.data() + 12, 8);
    if (payload_size != bytes.size() - kPrefixBytes)
      return bad("is truncated or padded (payload " + std::to_string(bytes.size() - kPrefixBytes) +
                 " bytes, header says " + std::to_string(payload_size) + ")");
    const std::uint8_t* payload = bytes.data() + kPrefixBytes;
    const auto sum = checksum(bytes.data(), payload, payload_size);
    if (sodium_memcmp(sum.data(), bytes.data() + kHeaderBytes, kChecksumBytes) != 0)
      return bad("fails its checksum (corrupt)");
    CborBudget budget;
    if (!json::sax_parse(payload, payload + payload_size, &budget, json::input_format_t::cbor, true))
      return bad("holds no well-formed CBOR within " + std::to_string(kMaxCborValues) + " values and depth " +
                 std::to_string(kMaxCborDepth));
    const json j = json::from_cbor(payload, payload + payload_size, true, true, json::cbor_tag_handler_t::error);
    ImageScene is = from_payload(j, key);
    bytes = {};
    try {
      is.scene = std::make_unique<Scene>(Scene::build(is.polylines, s.haptics.max_levels));
    } catch (const hk::Error& e) {
      return bad(std::string("holds curves the trees cannot be built from: ") + e.what());
    }
    if (is.scene->total_segments(0) != is.segments_after_budget)
      return bad("rebuilds to another number of level-0 segments");
    is.times.multires_ms = is.scene->build_times().multires_ms;
    is.times.tree_ms = is.scene->build_times().tree_ms;
    ::futimens(fd, nullptr);  // most recently used; a read-only folder keeps the old time
    return is;
  } catch (const BadEntry& e) {
    return bad(e.why);
  } catch (const json::exception& e) {
    return bad(std::string("holds a payload that is not a scene: ") + e.what());
  } catch (const std::exception& e) {
    spdlog::warn("scene cache: entry '{}' not loaded: {}", path, e.what());
    return std::nullopt;
  } catch (...) {
    spdlog::warn("scene cache: entry '{}' not loaded", path);
    return std::nullopt;
  }
}

void SceneCache::warn_once(const std::string& reason, const std::string& what) {
  const std::lock_guard lock(mutex_);
  if (warned_.insert(reason).second) spdlog::warn("scene cache: {}", what);
}

bool SceneCache::store(const std::string& key, const ImageScene& is) {
  if (dir_.empty()) return false;
  if (!is_key(key)) {
    warn_once("key", "'" + key + "' is not a scene key; nothing stored");
    return false;
  }
  if (is.text_pending || !is.scene) return false;  // not complete: its text is still to be read, or no trees
  std::vector<std::uint8_t> bytes;
  try {
    const json j = to_payload(key, is);
    bytes = entry_bytes(json::to_cbor(j));
  } catch (const BadEntry& e) {
    warn_once("encode", "a scene could not be stored: " + e.why);
    return false;
  } catch (const std::exception& e) {
    warn_once("encode", std::string("a scene could not be stored: ") + e.what());
    return false;
  }
  const auto size = static_cast<std::int64_t>(bytes.size());
  if (size > kSceneCacheMaxEntryBytes || size > max_bytes_) {
    warn_once("size", "a scene of " + std::to_string(size) + " bytes is larger than the cache of '" + dir_ +
                          "' keeps (" + std::to_string(std::min(max_bytes_, kSceneCacheMaxEntryBytes)) +
                          " bytes); not stored");
    return false;
  }
  const std::string failed = write_atomically(key + std::string(kSuffix), bytes);
  if (!failed.empty()) {
    warn_once(failed, "in '" + dir_ + "': cannot " + failed + "; built scenes are not kept");
    return false;
  }
  try {
    evict(key);
  } catch (const std::exception& e) {
    warn_once("evict", std::string("cannot keep '") + dir_ + "' under its size: " + e.what());
  }
  return true;
}

void SceneCache::evict(const std::string& keep) {
  const std::lock_guard lock(mutex_);
  struct Entry {
    std::string path;
    std::int64_t bytes;
    std::int64_t mtime_ns;
  };
  std::vector<Entry> entries;
  std::vector<std::string> refs;
  std::int64_t total = 0;
  const auto now = std::chrono::system_clock::now();
  std::error_code ec;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::string path = it->path().string();
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    const std::int64_t mtime_ns = static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
    if (name.starts_with(kTempPrefix)) {  // a crashed writer's, or one being written now (recent)
      const auto age =
          now - std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
                    std::chrono::nanoseconds(mtime_ns)));
      if (age > kStaleTemp) ::unlink(path.c_str());
      continue;
    }
    if (name.ends_with(kRefSuffix)) {
      refs.push_back(path);
      continue;
    }
    if (!name.ends_with(kSuffix) || !is_key(name.substr(0, name.size() - kSuffix.size()))) continue;
    total += st.st_size;
    if (name.substr(0, name.size() - kSuffix.size()) != keep) entries.push_back({path, st.st_size, mtime_ns});
  }
  if (total > max_bytes_) {
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      return a.mtime_ns != b.mtime_ns ? a.mtime_ns < b.mtime_ns : a.path < b.path;
    });
    for (const Entry& e : entries) {
      if (total <= max_bytes_) break;
      if (::unlink(e.path.c_str()) == 0 || errno == ENOENT) total -= e.bytes;
    }
  }
  // A ref whose entry is gone points nowhere: removed (a lookup through it would read the file anyway).
  for (const std::string& ref : refs) {
    std::array<char, kRefBytes> buf{};
    const int fd = ::open(ref.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) continue;
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    ::close(fd);
    const std::string key(buf.data(), n == static_cast<ssize_t>(kRefBytes) ? kRefBytes - 1 : 0);
    struct stat st {};
    if (!is_key(key) || ::stat(entry_path(key).c_str(), &st) != 0) ::unlink(ref.c_str());
  }
}

}  // namespace hk::app
