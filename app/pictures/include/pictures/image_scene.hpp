#pragma once
/// @file image_scene.hpp
/// Image file → haptic scene: vision's scene of the picture (vision/scene_chains.hpp: the curves a hand is
/// given, in workspace metres, and why the others were left out) and the multiresolution collision trees
/// (DESIGN.md "Data flow").

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "config/settings.hpp"
#include "formats/picture_notes.hpp"
#include "haptics/scene.hpp"
#include "meaning/names.hpp"
#include "meaning/shape_descriptors.hpp"
#include "vision/mapping.hpp"
#include "vision/ocr.hpp"
#include "vision/pdf.hpp"
#include "vision/pipeline.hpp"
#include "vision/scene_chains.hpp"

namespace hk::app {

/// Build time of each stage [ms].
struct BuildTimes {
  double load_ms = 0, edges_ms = 0, linking_ms = 0, thin_lines_ms = 0, gaps_ms = 0, multires_ms = 0, tree_ms = 0;
  /// Of load_ms, a picture file's checks and decoding (vision::load_image_reduced / decode_image_reduced);
  /// 0 for pixels already in memory (a camera capture, a rendered page).
  double decode_ms = 0;
  /// What the kiosk sees of the shapes (describe_scene_shapes): forms, colours, sizes; 0 when read from the cache.
  double descriptors_ms = 0;
  /// Faces guessed (describe_scene_shapes, meaning/faces.hpp); 0 when read from the cache or not looked for.
  double faces_ms = 0;
};

/// A block of text of a page in workspace metres: spoken, not felt.
struct TextBlockM {
  int id = 0;                  ///< index in ImageScene::text_blocks
  Vec2 lo_m, hi_m;             ///< bounding box [m]: lo = (x0, y0) lower left, hi = (x1, y1) upper right
  std::string text;            ///< its words in reading order (UTF-8)
  std::string source = "pdf";  ///< where the text came from: "pdf" (a PDF's text layer) or "ocr" (read from the pixels)
  double confidence = 1.0;     ///< how sure the reading is, [0, 1] (1 for a text layer; OCR: its words' mean)
  std::string language{};      ///< OCR: the language (BCP 47) most of its words were read in; "" unknown
  /// Whether the point p [m] lies in the box (edges included).
  bool contains(Vec2 p) const { return p.x >= lo_m.x && p.x <= hi_m.x && p.y >= lo_m.y && p.y <= hi_m.y; }
  /// Distance from p to the box [m] (0 inside).
  double distance_m(Vec2 p) const {
    const double dx = std::max({lo_m.x - p.x, 0.0, p.x - hi_m.x}), dy = std::max({lo_m.y - p.y, 0.0, p.y - hi_m.y});
    return std::hypot(dx, dy);
  }
};

/// How far around a text block a hand still finds it [m]: a line of a printed page is about 1 mm high in
/// the workspace, and lines are about as far apart, so the TextBlock cue's regions are the blocks grown by
/// this much (neighbouring lines' regions meet) and Describe reads the nearest block within 3 times it.
inline constexpr double kTextBlockReachM = 0.001;

/// The regions of the TextBlock cue (CueTracker::set_text_blocks): each block grown by kTextBlockReachM.
std::vector<Aabb> text_block_regions(const std::vector<TextBlockM>& blocks);

/// The block a hand at p is reading: the one containing p, else the nearest within 3 · kTextBlockReachM;
/// null when none.
const TextBlockM* text_block_at(const std::vector<TextBlockM>& blocks, Vec2 p);

/// What text reading (OCR) did for a scene: summary.json's "ocr".
struct OcrReport {
  bool ran = false;  ///< Tesseract read the picture
  /// Why it ran or not, one phrase: "off", "not a page of text", "a page of text", "always", "no text layer",
  /// "text layer covers little of the text", "a text layer", or what stopped it ("failed: ocr '...': ...").
  std::string why;
  int words = 0;               ///< words kept (in the text blocks)
  double mean_confidence = 0;  ///< over the kept words, [0, 1]
  double ms = 0;               ///< wall time of the worker [ms]
  long worker_max_rss_kb = 0;  ///< the worker's peak memory [KiB]
};

/// When a scene's text is read (OCR takes seconds a page).
enum class TextTiming {
  now,    ///< in the build: the scene comes back complete (explore, scripted runs, tests)
  later,  ///< the build only decides whether to read it; ImageScene::with_text reads it (the kiosk's TextReader)
};

struct ImageScene;

/// What a reading of a scene's text is given while it runs.
struct TextRun {
  /// Raised (may be null): the OCR worker is killed within 50 ms and the scene comes back without its text
  /// (OcrReport::why "cancelled").
  const std::atomic<bool>* cancel = nullptr;
  /// When given, called on the reading's thread with each text block's text and language (TextBlockM::language)
  /// as OCR reads it, in reading order (vision::OcrParams::on_block): the blocks the finished scene's text_blocks
  /// hold, the first of them seconds before the rest.
  std::function<void(const std::string& text, const std::string& language)> on_block;
};

/// Builds a scene again with its text read (OCR in its worker process, the words masked from the edges, the
/// blocks kept), as `run` says.
using TextBuild = std::function<ImageScene(const TextRun& run)>;

/// A picture turned into a scene. `polylines[i]` is the curve built into `scene` as the curve whose
/// `source_index` is i.
///
/// What was dropped and why, in pipeline order (each count is of the stage before it):
///   chains_found --thin-line merging--> chains_after_thin_lines --gap closing--> chains_after_gaps
///   = chains_too_short + chains_along_border + chains_over_max_shapes + chains_over_budget + polylines.size().
struct ImageScene {
  std::string image_path;         ///< the file (for a document page: the PDF)
  int page = 0;                   ///< document page shown (from 1); 0 for a picture file
  int pages = 0;                  ///< pages the document offers; 0 for a picture file
  std::string document_title;     ///< a PDF's own title (documents.hpp pdf_title), "" when none or a picture file
  std::string document_language;  ///< a PDF's language (its /Lang, vision::PdfPage::language), "" when it does not say
  /// A library picture's title and description (picture_notes.hpp), read where the scene was built (reading
  /// them parses the whole file, too slow for the window thread); empty for everything else.
  PictureNotes notes;
  /// What a library picture file itself says of it (embedded_notes: its metadata), read with its scene and
  /// kept with it in the scene cache; `notes` is this unless a sidecar says otherwise. Empty for the rest.
  PictureNotes file_notes;
  /// The BGR pixels the scene was built from, always set: a picture file's as decoded (at 1/decode_scale of
  /// its size, see picture_keep_side_px), a rendered page's, a camera capture's. px_to_m maps these pixels,
  /// so the picture is shown from here (never decoded again from image_path).
  cv::Mat picture;
  /// The picture's own size at full detail [px], upright as `picture` is: a picture file's (its EXIF
  /// orientation applied), otherwise picture's size.
  int file_width_px = 0, file_height_px = 0;
  /// Full-detail pixels per `picture` pixel along each side: 1, 2, 4 or 8 (a JPEG decoded reduced, "decoded at
  /// 1/4"); 1 for everything else.
  int decode_scale = 1;
  std::vector<TextBlockM> text_blocks;  ///< a page's text blocks (masked from the edges), in reading order
  OcrReport ocr;                        ///< whether the text was read from the pixels, and how it went
  /// The text is still to be read (built with TextTiming::later and OCR wanted): the curves are the
  /// picture's with the letters of printed lines kept out (vision::printed_letters_mask), there are no OCR
  /// text blocks yet, and `with_text` reads them.
  bool text_pending = false;
  /// With text_pending: the picture looks like a page of text (printed lines were found), so the kiosk says
  /// "Reading the text." with it at once; false for a picture page of a PDF without a text layer, which is
  /// read all the same but may well hold no text.
  bool text_likely = false;
  TextBuild with_text;                ///< set with text_pending; slow (seconds): call it off the window thread
  std::size_t text_words_masked = 0;  ///< words whose outlines were kept out of the edges
  double render_dpi = 0;              ///< a PDF page: the DPI it was drawn at
  double worker_ms = 0;               ///< a PDF page: wall time of the drawing worker [ms]
  long worker_max_rss_kb = 0;         ///< a PDF page: the worker's peak memory [KiB]
  int width_px = 0, height_px = 0;    ///< size of `picture` [px] (what px_to_m maps)
  vision::PxToM px_to_m{};
  std::size_t chains_texture = 0;  ///< dropped before chains_found: edges that do not stand out from their surround
                                   ///< (detector "surround", vision::stands_out)
  std::size_t chains_found = 0;    ///< chains out of edge linking (after the texture test)
  std::size_t thin_line_pairs_merged = 0;  ///< pairs of facing edges (two sides of a stroke thinner than
                                           ///< vision.thin_line_max_width_m) felt as one centre line
  std::size_t chains_after_thin_lines =
      0;                        ///< chains after thin-line merging (centre lines, left-over pieces, untouched chains)
  std::size_t gaps_closed = 0;  ///< chain ends joined across a gap of at most vision.gap_close_m (vision::close_gaps)
  std::size_t chains_closed_by_gaps = 0;  ///< chains that came out closed from those joins
  std::size_t chains_after_gaps = 0;      ///< chains after gap closing
  std::size_t chains_too_short = 0;       ///< dropped: shorter than vision.min_chain_length_m
  std::size_t chains_along_border =
      0;  ///< dropped: running along the picture's frame (border_share >= kBorderShare), not shapes
  std::size_t chains_over_max_shapes = 0;  ///< dropped: vision.max_shapes more salient curves were kept
  std::size_t chains_over_budget = 0;  ///< dropped: the scene would hold more than vision.max_segments level-0 segments
                                       ///< (least salient dropped first)
  std::size_t segments_before_budget = 0;  ///< level-0 segments of the scene of every curve long enough to feel
  std::size_t segments_after_budget = 0;   ///< level-0 segments of the scene built (<= vision.max_segments)
  double canny_low = 0, canny_high = 0;  ///< Canny's thresholds; for traced outlines low = 0, high = the sure strength
                                         ///< (vision::Extraction::edge_map)
  vision::Detector detector =
      vision::Detector::Canny;  ///< how the boundaries were found (what [vision] detector "auto" chose)
  vision::TwoTone tones;        ///< the picture's two tones, when it was classified
  /// A two-tone picture whose ink (tones.ink_width_px, in metres at the workspace scale) is at most
  /// vision.thin_line_max_width_m: a line drawing, found by Canny and its strokes merged to centre lines.
  bool line_drawing = false;
  std::vector<Polyline> polylines;  ///< kept chains in workspace metres
  /// strength[i]: mean edge strength along polylines[i], in Canny threshold units (the Sobel-3x3 L2
  /// gradient magnitude Canny thresholded, vision::Extraction::point_strength; a centre line takes
  /// the mean of its two sides).
  std::vector<double> strength;
  /// descriptors[i]: what polylines[i] looks like (meaning/shape_descriptors.hpp), one per polyline.
  std::vector<meaning::ShapeDescriptor> descriptors;
  /// Faces guessed in the picture (meaning/faces.hpp), boxes in workspace metres (lo = lower left); kept in the
  /// scene cache. Not looked for on document pages and two-tone pictures (silhouettes, line drawings).
  std::vector<Aabb> faces_m;
  /// Regions named on `picture`: staff's, then the guesses (faces, text blocks) that staff's do not cover
  /// (picture_names.hpp apply_names; not kept in the scene cache).
  std::vector<meaning::NamedRegion> regions;
  /// shape_region[i]: the region polylines[i] takes its name from, −1 for none; empty before apply_names.
  std::vector<int> shape_region;
  std::unique_ptr<Scene> scene;  ///< collision trees (heap: the servo loop holds a pointer)
  BuildTimes times;
};

/// Longest side of the picture a screen shows [px]: a full-HD screen's width (the workspace never fills more).
inline constexpr int kScreenPictureMaxSidePx = 1920;

/// Sets `is.descriptors` (one per polyline: form, colour, size, speck) from its polylines, its scene (the form's
/// coarse level; without a scene, each polyline's own points) and its picture (the colours; none when empty),
/// timed in is.times.descriptors_ms; and `is.faces_m` (meaning/find_faces on the picture; not looked for on a
/// document page, a two-tone picture or an empty one), timed in is.times.faces_ms. Call after the scene is built and
/// before fit_picture shrinks the picture. Never throws but std::bad_alloc.
void describe_scene_shapes(ImageScene& is);

/// Shrinks `is.picture` (INTER_AREA) so that its long side is at most `max_side_px`, and moves `is.px_to_m`
/// with it (pixel centres kept: the same workspace rectangle), so the picture shown is no larger than a screen
/// needs and crosses to the GPU in one small upload. The curves, text blocks and scene are untouched (they are
/// in metres). Nothing happens to an empty or small enough picture.
/// @throws hk::ArgumentError if max_side_px < 1.
void fit_picture(ImageScene& is, int max_side_px = kScreenPictureMaxSidePx);

/// Memory an ImageScene holds [bytes], roughly: its picture, its curves and its collision trees (about 150
/// bytes a level-0 segment over all levels and boxes; Scene's own layout, scene.hpp). What budgets of scenes
/// built ahead ([kiosk] prefetch_mb) count. Never throws.
std::size_t approx_scene_bytes(const ImageScene& is);

/// Polyline length [m], with the closing segment of a closed curve (what a hand can follow).
double polyline_length_m(const Polyline& p);

/// vision's curves as haptics' polylines (same points, same closedness).
std::vector<Polyline> to_polylines(const std::vector<vision::SceneCurve>& curves);

/// Fewest pixels the long side of a picture file is decoded at for its scene [px]: [vision]
/// max_image_side_px, or at least kPictureTextJudgedMinSidePx when [vision] ocr is not "off" (whether it is a
/// page of text is judged at up to 1600 px and must see its letters). A JPEG or PNG is decoded at the
/// largest reduction 1/2, 1/4 or 1/8 that keeps this many (vision::decode_reduction_for).
int picture_keep_side_px(const config::Settings& settings);

/// The least long side a picture is decoded at when its text may be read [px] (picture_keep_side_px).
inline constexpr int kPictureTextJudgedMinSidePx = 1200;

/// Loads the image at `path` and builds its scene with `settings`: text read from it when [vision] ocr asks
/// (wants_picture_text, read_text), then vision::scene_chains_from_image with the words and the letters of
/// printed lines (printed_letters_mask_of: words too uncertain to speak are no shapes either) masked (extraction, thin
/// lines, gaps, pixels → metres, the budgets; the [vision] and [workspace] settings, each curve priced at the level-0
/// segments plan_levels gives it), then Scene::build (haptics.max_levels) of the curves kept. `timing` later: the text
/// is not read here (ImageScene::text_pending, with_text). The file is decoded by vision::load_image_reduced at
/// picture_keep_side_px (a large JPEG or PNG at 1/2, 1/4 or 1/8: ImageScene::picture, decode_scale, file_width_px,
/// file_height_px). When its text is read and the decode was reduced, the file is decoded again for OCR at up to
/// kOcrMaxSidePx (all intake checks again) and the words' boxes are scaled into `picture`'s pixels; if that second
/// decode is refused, the picture is felt without its text (OcrReport::why "failed: ..."). Throws vision::InputError
/// for bad image files (one line naming the file and the limit).
ImageScene build_image_scene(const std::string& path, const config::Settings& settings,
                             TextTiming timing = TextTiming::now);

/// build_image_scene on a picture's bytes already read (a document from a USB stick, read once through
/// vision::read_stick_file): vision::decode_image_reduced with the [vision] limits at picture_keep_side_px, then
/// the same steps. `name` names it in errors and scene.json; ImageScene::picture holds the decoded pixels.
/// When OCR needs more detail than the reduced decode kept, a copy of `bytes` is kept (shared by
/// ImageScene::with_text) and decoded again for it.
/// @throws vision::InputError (one line naming `name` and the limit).
ImageScene build_image_scene_from_bytes(const std::vector<std::uint8_t>& bytes, const std::string& name,
                                        const config::Settings& settings, TextTiming timing = TextTiming::now);

/// build_image_scene on pixels already in memory (a camera capture): the same steps from
/// vision::scene_chains_from_image. `name` names it in errors and scene.json; ImageScene::picture holds a copy.
/// @throws hk::ArgumentError for an empty or non-CV_8UC3 image (and as scene_chains_from_image).
ImageScene build_image_scene_from_picture(const cv::Mat& bgr, const std::string& name, const config::Settings& settings,
                                          TextTiming timing = TextTiming::now);

/// wants_page_text's answer for a page: whether its text is read from its pixels, and why.
struct PageTextChoice {
  bool read = false;
  std::string why;  ///< in OcrReport::why's words
};

/// Builds the scene of a rendered document page the way build_image_scene builds a picture's, except that
/// text is spoken, not felt: its words (the text layer's, or OCR's when wants_page_text) each have their box,
/// grown by a quarter of its height on each side (the blurred glyphs' edges reach past the box), masked from
/// edge detection (vision::extract_chains_from_image), and the page's text blocks are kept in metres for the
/// earcon, Where and Describe. When OCR is wanted the letters of printed lines are masked too. Figures, rules
/// and drawings stay curves.
/// `timing` later: OCR's words are not read here (ImageScene::text_pending, with_text); meanwhile the text
/// layer's words and the letters of printed lines are masked.
/// @param name  the document's name for scene.json and messages (image_path).
/// @param choice  wants_page_text's answer for this page when the caller has it, so the page is not judged
///        twice; null: judged here.
ImageScene build_page_scene(const vision::PdfPage& page, const std::string& name, int page_number,
                            const config::Settings& settings, TextTiming timing = TextTiming::now,
                            const PageTextChoice* choice = nullptr);

/// The mask of a page's text for vision::extract_chains_from_image: CV_8UC1 of `size`, 255 inside each
/// word box grown by `grow` x its height on every side, 0 elsewhere.
cv::Mat text_mask(cv::Size size, const std::vector<vision::PdfWord>& words, double grow = 0.25);

/// Longest side a picture is read at [px]: a letter-size page at 400 dpi. Larger pictures (a 24-megapixel
/// photo of a page) are scaled down to it first.
inline constexpr int kOcrMaxSidePx = 4400;

/// Whether the text of a picture is read: [vision] ocr "off" never, "always" always, "auto" when the picture
/// looks like a page of text (vision::looks_like_text_page, judged at up to 1600 px). `why` gets the reason
/// in OcrReport::why's words.
bool wants_picture_text(const cv::Mat& grey, const config::Settings& settings, std::string& why);

/// Whether a rendered PDF page's text is read from its pixels: [vision] ocr "off" never; otherwise when it
/// has no text layer (a scanned page), or when the page with its text layer's words whited out still looks
/// like a page of text (the layer leaves most of the text out). `why` as wants_picture_text.
bool wants_page_text(const vision::PdfPage& page, const config::Settings& settings, std::string& why);

/// Reads the text of `grey` (CV_8UC1) with vision::recognise_text at up to kOcrMaxSidePx; the words come back
/// in `grey`'s pixel frame. Fills `report` (ran, words, confidence, time, memory). A failure (OcrError) is
/// logged in one line and costs the text only: report.why says what happened ("cancelled" when run.cancel was
/// raised), the result is empty. run.on_block hears each block as it is read.
vision::OcrResult read_text(const cv::Mat& grey, const std::string& name, const config::Settings& settings,
                            OcrReport& report, const TextRun& run = {});

/// Where the letters of printed lines lie in `grey` (vision::printed_letters_mask judged at up to 1600 px,
/// scaled back to grey's size); empty when it is not a page of text. What a page's curves leave out until
/// OCR has read its words.
cv::Mat printed_letters_mask_of(const cv::Mat& grey);

}  // namespace hk::app
