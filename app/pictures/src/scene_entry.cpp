// The scene cache's entry format (scene_entry.hpp).
#include "pictures/scene_entry.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pictures/scene_cache.hpp"

namespace hk::app {
namespace {

using json = nlohmann::json;

constexpr std::array<std::uint8_t, 8> kMagic = {'H', 'K', 'S', 'C', 'E', 'N', 'E', '\0'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 8;                   // magic, format, payload size
constexpr std::size_t kChecksumBytes = crypto_generichash_BYTES;  // 32
constexpr std::size_t kPrefixBytes = kHeaderBytes + kChecksumBytes;
/// CBOR values a payload may hold: far above a scene's (a few hundred per curve at most, the points being
/// byte strings), far below what would make the parsed tree large (about 100 bytes a value).
constexpr std::size_t kMaxCborValues = 1u << 20;
constexpr std::size_t kMaxCborDepth = 8;
/// Largest picture an entry may hold [px]: the decoded picture is allocated from the JPEG's own header.
constexpr std::int64_t kMaxPicturePixels = 100'000'000;

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

/// The shapes' descriptors as a payload array: {form, corners, colour (absent when unknown), size_cm, length_m,
/// speck} each.
json descriptors_json(const std::vector<meaning::ShapeDescriptor>& ds) {
  json out = json::array();
  for (const meaning::ShapeDescriptor& d : ds) {
    json e = {{"form", meaning::form_key(d.form.form)},
              {"corners", d.form.corners},
              {"size_cm", d.size_cm},
              {"length_m", d.length_m},
              {"speck", d.speck}};
    if (d.has_colour) e["colour"] = meaning::colour_words(d.colour);
    out.push_back(std::move(e));
  }
  return out;
}

/// A payload's descriptors, one per polyline. Throws BadEntry on a form or colour it does not know.
void descriptors_from(const json& a, ImageScene& is) {
  for (const json& e : a) {
    meaning::ShapeDescriptor d;
    if (!meaning::form_from_key(e.at("form").get<std::string>(), &d.form.form)) throw BadEntry{"an unknown form"};
    d.form.corners = e.at("corners").get<int>();
    d.size_cm = e.at("size_cm").get<double>();
    d.length_m = e.at("length_m").get<double>();
    d.speck = e.at("speck").get<bool>();
    d.has_colour = e.contains("colour");
    if (d.has_colour && !meaning::colour_from_words(e.at("colour").get<std::string>(), &d.colour))
      throw BadEntry{"an unknown colour"};
    is.descriptors.push_back(d);
  }
  if (is.descriptors.size() != is.polylines.size()) throw BadEntry{"descriptors and polylines differ in count"};
}

/// The faces guessed as a payload array of [lo.x, lo.y, hi.x, hi.y] boxes [m].
json faces_json(const std::vector<Aabb>& faces) {
  json out = json::array();
  for (const Aabb& f : faces) out.push_back({f.lo.x, f.lo.y, f.hi.x, f.hi.y});
  return out;
}

/// A payload's faces. Throws BadEntry on a box that is not 4 numbers with lo below hi.
void faces_from(const json& a, ImageScene& is) {
  for (const json& e : a) {
    if (!e.is_array() || e.size() != 4) throw BadEntry{"a face is not 4 numbers"};
    const Aabb f{{e[0].get<double>(), e[1].get<double>()}, {e[2].get<double>(), e[3].get<double>()}};
    if (!(f.lo.x <= f.hi.x && f.lo.y <= f.hi.y)) throw BadEntry{"a face's box is upside down"};
    is.faces_m.push_back(f);
  }
}

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
  j["document_language"] = is.document_language;
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
  if (is.descriptors.size() == is.polylines.size()) j["descriptors"] = descriptors_json(is.descriptors);
  j["faces_m"] = faces_json(is.faces_m);
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
  is.document_language = j.value("document_language", std::string());  // entries written before it was kept
  if (j.contains("picture")) is.picture = picture_from(j.at("picture"));
  text_from(j, is);
  geometry_from(j, is);
  counts_from(j.at("counts"), is);
  detection_from(j, is);
  curves_from(j, is);
  if (j.contains("descriptors")) descriptors_from(j.at("descriptors"), is);
  if (j.contains("faces_m")) faces_from(j.at("faces_m"), is);
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

}  // namespace

bool is_key(const std::string& k) {
  return k.size() == 2 * crypto_generichash_BYTES &&
         std::all_of(k.begin(), k.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

std::vector<std::uint8_t> encode_entry(const std::string& key, const ImageScene& is) {
  const std::vector<std::uint8_t> payload = json::to_cbor(to_payload(key, is));
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

ImageScene decode_entry(const std::vector<std::uint8_t>& bytes, const std::string& key) {
  if (!std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) throw BadEntry{"is not a scene entry (wrong magic)"};
  const auto format = static_cast<std::uint32_t>(get_le(bytes.data() + 8, 4));
  if (format != kSceneCacheFormat)
    throw BadEntry{"is of format " + std::to_string(format) + ", not " + std::to_string(kSceneCacheFormat) +
                   " (stale)"};
  const std::uint64_t payload_size = get_le(bytes.data() + 12, 8);
  if (payload_size != bytes.size() - kPrefixBytes)
    throw BadEntry{"is truncated or padded (payload " + std::to_string(bytes.size() - kPrefixBytes) +
                   " bytes, header says " + std::to_string(payload_size) + ")"};
  const std::uint8_t* payload = bytes.data() + kPrefixBytes;
  const auto sum = checksum(bytes.data(), payload, payload_size);
  if (sodium_memcmp(sum.data(), bytes.data() + kHeaderBytes, kChecksumBytes) != 0)
    throw BadEntry{"fails its checksum (corrupt)"};
  CborBudget budget;
  if (!json::sax_parse(payload, payload + payload_size, &budget, json::input_format_t::cbor, true))
    throw BadEntry{"holds no well-formed CBOR within " + std::to_string(kMaxCborValues) + " values and depth " +
                   std::to_string(kMaxCborDepth)};
  try {
    const json j = json::from_cbor(payload, payload + payload_size, true, true, json::cbor_tag_handler_t::error);
    return from_payload(j, key);
  } catch (const json::exception& e) {
    throw BadEntry{std::string("holds a payload that is not a scene: ") + e.what()};
  }
}

}  // namespace hk::app
