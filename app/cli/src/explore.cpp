// Headless explore run: image → scene → simulated pantograph + model hand → servo ticks → files.
#include "cli/explore.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "audio/mixer.hpp"
#include "audio/wav.hpp"
#include "config/load.hpp"
#include "formats/picture_notes.hpp"
#include "haptics/explorer_hand.hpp"
#include "haptics/hand_path.hpp"
#include "haptics/servo.hpp"
#include "haptics/tolerance_cut.hpp"
#include "hk/level_choice.hpp"
#include "meaning/shape_descriptors.hpp"
#include "pictures/capture.hpp"
#include "pictures/documents.hpp"
#include "pictures/image_scene.hpp"
#include "pictures/picture_names.hpp"
#include "pictures/picture_params.hpp"
#include "runtime/coverage.hpp"
#include "runtime/cue_tracker.hpp"
#include "runtime/runtime_params.hpp"
#include "runtime/simulation.hpp"
#include "visit/describe.hpp"

namespace hk::app {
namespace {

using json = nlohmann::json;

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f << text;
  f.close();
  if (!f) throw ExploreError("output '" + p.string() + "': cannot write the file");
}

/// Whether the sidecar of picture file `path` lets the kiosk's guesses name its parts (`guesses`); a sidecar that
/// cannot be used is read as none (the kiosk shows the picture without its notes).
bool guesses_wanted(const std::string& path) {
  try {
    return read_picture_notes(path).guesses;
  } catch (const PictureNotesError&) {
    return true;
  }
}

/// A curve's `name` and `name_source` in scene.json: its region's ("staff", or a guess: "face", "text"), else its
/// form's look ("form": "small red round shape", sizes against the workspace of half extents `half_m` [m]) when it
/// has a form; neither for an irregular shape without a name.
void add_curve_name(json& curve, const ImageScene& is, std::size_t source, Vec2 half_m) {
  if (source < is.shape_region.size() && is.shape_region[source] >= 0) {
    const meaning::NamedRegion& r = is.regions[static_cast<std::size_t>(is.shape_region[source])];
    curve["name"] = r.name;
    curve["name_source"] = meaning::region_source_key(r.source);
    return;
  }
  if (source >= is.descriptors.size() || is.descriptors[source].form.form == meaning::Form::irregular) return;
  std::string look = describe_one_look(is.polylines, is.descriptors, source, half_m);
  curve["name"] = look.substr(look.find(' ') + 1);  // without its article
  curve["name_source"] = "form";
}

/// The named regions of `is` that name no curve: scene.json's `regions` [{name, description, bbox_m}].
json unnamed_regions_json(const ImageScene& is) {
  json out = json::array();
  for (std::size_t r = 0; r < is.regions.size(); ++r) {
    if (std::find(is.shape_region.begin(), is.shape_region.end(), static_cast<int>(r)) != is.shape_region.end())
      continue;
    const meaning::NamedRegion& nr = is.regions[r];
    const cv::Rect& b = nr.box_px;
    json e = {{"name", nr.name},
              {"name_source", meaning::region_source_key(nr.source)},
              {"bbox_m",
               {is.px_to_m.x_m(b.x - 0.5), is.px_to_m.y_m(b.y + b.height - 0.5), is.px_to_m.x_m(b.x + b.width - 0.5),
                is.px_to_m.y_m(b.y - 0.5)}}};
    if (!nr.description.empty()) e["description"] = nr.description;
    out.push_back(std::move(e));
  }
  return out;
}

json scene_json(const ImageScene& is, const config::Settings& s) {
  json j;
  j["image"] = {{"path", is.image_path}, {"width_px", is.width_px}, {"height_px", is.height_px}};
  j["px_to_m"] = {{"scale", is.px_to_m.scale_m_per_px},
                  {"offset_x_m", is.px_to_m.offset_x_m},
                  {"offset_y_m", is.px_to_m.offset_y_m}};
  j["stiffness_n_per_m"] = s.haptics.stiffness_n_per_m;
  j["max_force_n"] = s.haptics.max_force_n;
  j["level_in_use"] = s.haptics.level;
  json curves = json::array();
  const Scene& sc = *is.scene;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const CurveInfo& ci = sc.curve(c);
    json levels = json::array();
    for (int l = 0; l < ci.levels; ++l) {
      json pts = json::array();
      const Vec2* p = sc.points(c, l);
      for (std::uint32_t i = 0; i < ci.point_count[l]; ++i) pts.push_back({p[i].x, p[i].y});
      levels.push_back({{"level", l},
                        {"points_m", std::move(pts)},
                        {"max_error_m", ci.max_error_m[l]},
                        {"max_box_half_width_m", ci.max_box_half_width_m[l]},
                        {"max_error_bound_m", ci.max_error_bound_m[l]}});
    }
    json curve = {{"id", c}, {"closed", ci.closed}, {"levels", std::move(levels)}};
    const std::size_t source = sc.source_index(c);
    add_curve_name(curve, is, source, {s.workspace.width_m / 2, s.workspace.height_m / 2});
    if (source < is.descriptors.size()) {
      const meaning::ShapeDescriptor& d = is.descriptors[source];
      json desc = {{"form", meaning::form_key(d.form.form)}, {"size_cm", d.size_cm}};
      if (d.has_colour) desc["colour"] = meaning::colour_words(d.colour);
      if (d.form.form == meaning::Form::polygon || d.form.form == meaning::Form::star) desc["corners"] = d.form.corners;
      curve["descriptors"] = std::move(desc);
      curve["speck"] = d.speck;
    }
    curves.push_back(std::move(curve));
  }
  j["curves"] = std::move(curves);
  j["regions"] = unnamed_regions_json(is);
  if (is.page > 0) {
    j["page"] = is.page;
    j["pages"] = is.pages;
  }
  if (is.page > 0 || !is.text_blocks.empty()) {  // a page with text: its text is spoken, not felt
    json blocks = json::array();
    for (const TextBlockM& b : is.text_blocks) {
      blocks.push_back({{"id", b.id},
                        {"bbox_m", {b.lo_m.x, b.lo_m.y, b.hi_m.x, b.hi_m.y}},
                        {"text", b.text},
                        {"source", b.source},
                        {"confidence", b.confidence}});
    }
    j["text_blocks"] = std::move(blocks);
  }
  return j;
}

cv::Point2d to_px(const vision::PxToM& m, Vec2 q) { return {m.u_px(q.x), m.v_px(q.y)}; }

void write_overlay(const std::filesystem::path& out, const ImageScene& is, int level,
                   const std::vector<Vec2>& proxy_path) {
  if (is.picture.empty())
    throw ExploreError("image '" + is.image_path + "': the scene holds no picture for the overlay");
  cv::Mat img = is.picture.clone();
  // Dim the picture so the drawn curves stand out; draw at 4x sub-pixel precision.
  img = img * 0.55;
  const int thick = std::max(1, static_cast<int>(std::lround(std::max(img.cols, img.rows) / 400.0)));
  constexpr int kShift = 2;
  auto fixed = [&](cv::Point2d p) {
    return cv::Point(static_cast<int>(std::lround(p.x * 4)), static_cast<int>(std::lround(p.y * 4)));
  };
  const Scene& sc = *is.scene;
  const LevelChoice choice = LevelChoice::of_id(level);
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const int l = sc.clamp_level(c, level);
    std::vector<cv::Point> pts;
    if (choice.kind == LevelChoice::Kind::Cut) {  // a cut step: the cut's joined polyline, what the walls were
      std::vector<SegmentRef> cut;
      tolerance_cut(sc, c, kToleranceLadder_m[choice.index], &cut);
      for (const Vec2& p : joined_cut_points(sc, c, cut.data(), cut.size())) pts.push_back(fixed(to_px(is.px_to_m, p)));
    } else {
      const Vec2* p = sc.points(c, l);
      for (std::uint32_t i = 0; i < sc.curve(c).point_count[l]; ++i) pts.push_back(fixed(to_px(is.px_to_m, p[i])));
    }
    cv::polylines(img, pts, sc.curve(c).closed, cv::Scalar(0, 220, 255), thick, cv::LINE_AA, kShift);
  }
  std::vector<cv::Point> path;
  const std::size_t stride = std::max<std::size_t>(1, proxy_path.size() / 20000);
  for (std::size_t i = 0; i < proxy_path.size(); i += stride) path.push_back(fixed(to_px(is.px_to_m, proxy_path[i])));
  if (path.size() > 1)
    cv::polylines(img, path, false, cv::Scalar(255, 120, 40), std::max(1, thick / 2), cv::LINE_AA, kShift);
  if (!cv::imwrite(out.string(), img)) throw ExploreError("output '" + out.string() + "': cannot write the PNG");
}

double percentile(std::vector<std::int64_t>& v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return static_cast<double>(v[k]);
}

// --source: one capture (capture.hpp; a time-out keeps the last frame), written beside the outputs as capture.png
// and capture.json, and the scene of what it captured.
ImageScene build_capture_scene(const std::string& spec_text, int page, const config::Settings& s,
                               const std::filesystem::path& out) {
  if (page > 0) throw ExploreError("--page " + std::to_string(page) + ": a camera capture has no pages");
  const vision::SourceSpec spec = vision::parse_source_spec(spec_text);
  std::unique_ptr<vision::FrameSource> source = vision::open_frame_source(spec, frame_source_params_from(s));
  const CaptureOutcome captured = run_capture(*source, capture_params_from(s));
  write_capture(captured, source->name(), out.string());
  return build_image_scene_from_picture(captured.image, spec.str(), s);
}

}  // namespace

std::uint64_t parse_seed(const std::string& text) {
  const std::string limit = "' is not a whole number in [0, 9223372036854775807]";
  if (text.empty() || text.size() > 19) throw ExploreError("--seed '" + text + limit);
  std::uint64_t v = 0;
  for (char ch : text) {
    if (ch < '0' || ch > '9') throw ExploreError("--seed '" + text + limit);
    v = v * 10 + static_cast<std::uint64_t>(ch - '0');
  }
  if (v > 9223372036854775807ULL) throw ExploreError("--seed '" + text + limit);
  return v;
}

ImageScene build_input_scene(const std::string& path, int page, const config::Settings& s) {
  if (page < 0) throw ExploreError("--page " + std::to_string(page) + " is outside [1, pages of the document]");
  if (!is_pdf_file(path)) {
    if (page > 0)
      throw ExploreError("--page " + std::to_string(page) + ": '" + path +
                         "' is not a PDF (pages are for PDF documents)");
    return build_image_scene(path, s);
  }
  return build_pdf_page_scene(vision::read_input_file(path, s.stick.max_file_bytes), path, page > 0 ? page : 1, s);
}

namespace {

// The run's settings: the file's (or the defaults); on the emulated board, fitted to its profile's forces
// and stiffness, as the kiosk fits them when it takes a board.
config::Settings explore_settings(const ExploreOptions& o, const DeviceChoice& device) {
  config::Settings s = o.config_path.empty() ? config::Settings{} : config::load_settings(o.config_path);
  if (device.kind == DeviceChoice::Kind::HaplyEmulator) {
    std::vector<std::string> notes;
    s = settings_for_board(s, &notes);
    for (const std::string& n : notes) spdlog::warn("device: {}", n);
  }
  return s;
}

// The path of --hand: the raster (also the explorer's fallback duration) or a hand file's, read before the
// slower image so a bad hand file fails fast.
HandPath hand_path_of(const ExploreOptions& o, const config::Settings& s, const DeviceChoice& device) {
  const bool explorer = o.hand == "explorer";
  if (explorer && device.kind == DeviceChoice::Kind::HaplyEmulator) {
    throw ExploreError(
        "--hand explorer: the explorer needs the device's force each tick, which only --device sim gives");
  }
  if (o.hand == "raster" || explorer) {
    return raster_path(s.workspace.width_m, s.workspace.height_m, s.hand.raster_spacing_m, s.hand.raster_speed_m_per_s);
  }
  return load_hand_csv(o.hand);
}

// The model hand of --hand: the explorer, or a PathHand on `path` (which outlives it).
std::unique_ptr<HandController> make_hand(const ExploreOptions& o, const config::Settings& s, const HandPath& path) {
  if (o.hand == "explorer") return std::make_unique<ExplorerHand>(explorer_params_from(s, o.seed));
  return std::make_unique<PathHand>(path, s.hand.max_force_n);
}

std::filesystem::path make_out_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw ExploreError("output folder '" + dir + "': cannot create it (" + ec.message() + ")");
  return std::filesystem::path(dir);
}

// --audio-out names a .wav file in an existing folder, for a run of at most an hour.
void check_audio_out(const std::string& audio_out, double duration_s) {
  if (audio_out.empty()) return;
  const std::filesystem::path a(audio_out);
  std::string ext = a.extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext != ".wav") throw ExploreError("--audio-out '" + audio_out + "': must name a .wav file");
  const std::filesystem::path parent = a.has_parent_path() ? a.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(parent))
    throw ExploreError("--audio-out '" + audio_out + "': folder '" + parent.string() + "' does not exist");
  if (duration_s > 3600.0) {
    throw ExploreError("--audio-out '" + audio_out + "': a run of " + std::to_string(duration_s) +
                       " s is over the audio limit of 3600 s");
  }
}

/// One row of trace.csv.
struct TraceRow {
  double t_s;
  Vec2 handle_m, proxy_m, force_n;
  int contact, curve, level;
  std::int64_t tick_ns;
  int pop;
};

/// What explore keeps of every tick: the trace's rows (formatted after the run: printf between ticks would
/// evict the servo's data from the caches and inflate the tick times measured), the earcons, and the counts
/// summary.json reports.
struct RunRecord {
  std::vector<TraceRow> rows;
  std::vector<std::int64_t> tick_ns;
  std::vector<Vec2> proxy_path;
  std::vector<audio::CueEvent> cues;
  ExploreSummary sum;
  long budget_exhausted = 0, section_max = 0, iteration_limited = 0;
  double queries = 0, box_tests = 0, section_sum = 0;
  long level_changes = 0, level_waiting = 0, sticking = 0, pops = 0;
  std::array<long, kLevelIds> level_ticks{};  // per level id (levels and tolerance steps)
  CoverageMeter coverage{0.001};

  void add(const ServoTick& r, const ServoOutput& so) {
    const ContactOutput& c = so.contact;
    const int state = static_cast<int>(c.state);
    const int curve = c.state == ContactState::Free ? -1 : c.constraint[0].curve;
    const int pop = (c.events & kEventPopThrough) != 0;
    rows.push_back({r.t_s, r.sample.handle_m, c.proxy_m, so.force_n, state, curve, c.level, r.step_ns, pop});
    pops += pop;
    tick_ns.push_back(r.step_ns);
    proxy_path.push_back(c.proxy_m);
    coverage.add(c.proxy_m, curve, c.state == ContactState::Vertex ? c.constraint[1].curve : -1);
    ++sum.ticks;
    sum.free_ticks += state == 0;
    sum.edge_ticks += state == 1;
    sum.vertex_ticks += state == 2;
    sum.max_force_n = std::max(sum.max_force_n, length(so.force_n));
    budget_exhausted += c.query.budget_exhausted;
    queries += c.queries;
    box_tests += c.query.box_tests;
    section_sum += c.query.section_size;
    section_max = std::max<long>(section_max, c.query.section_size);
    iteration_limited += (c.events & kEventIterationLimit) != 0;
    level_changes += so.level_changed;
    level_waiting += so.level != so.level_wanted;
    sticking += c.sticking;
    if (so.level >= 0 && so.level < kLevelIds) ++level_ticks[static_cast<std::size_t>(so.level)];
  }
};

// The servo run itself: the kiosk's runner over the chosen device, the earcons drained after every tick.
void run_servo(const Scene& scene, const ImageScene& is, const config::Settings& s, HandController& hand,
               double duration_s, const DeviceChoice& device, RunRecord& rec) {
  rec.rows.reserve(static_cast<std::size_t>(std::ceil(duration_s * s.haptics.servo_rate_hz)) + 1);
  audio::SpscRing<audio::CueEvent> cue_ring(64);
  RunOptions run;
  run.device = device;
  run.report = &rec.sum.device;
  run.cues = &cue_ring;
  run.text_blocks_m = text_block_regions(is.text_blocks);
  run_simulation(
      scene, s, hand, duration_s,
      [&](const ServoTick& r, const ServoOutput& so) {
        for (audio::CueEvent e; cue_ring.try_pop(e);) rec.cues.push_back(e);
        rec.add(r, so);
      },
      run);
  rec.sum.curves = scene.curve_count();
  rec.sum.cues = rec.cues.size();
}

void write_trace(const std::filesystem::path& trace_path, const std::vector<TraceRow>& rows) {
  std::unique_ptr<FILE, int (*)(FILE*)> trace(std::fopen(trace_path.c_str(), "w"), &std::fclose);
  if (!trace) throw ExploreError("output '" + trace_path.string() + "': cannot open for writing");
  static char buffer[1 << 16];
  std::setvbuf(trace.get(), buffer, _IOFBF, sizeof buffer);
  std::fputs("t_s,handle_x_m,handle_y_m,proxy_x_m,proxy_y_m,force_x_n,force_y_n,contact,curve,level,tick_ns,pop\n",
             trace.get());
  for (const TraceRow& w : rows) {
    std::fprintf(trace.get(), "%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%d,%lld,%d\n", w.t_s, w.handle_m.x,
                 w.handle_m.y, w.proxy_m.x, w.proxy_m.y, w.force_n.x, w.force_n.y, w.contact, w.curve, w.level,
                 static_cast<long long>(w.tick_ns), w.pop);
  }
  if (std::fflush(trace.get()) != 0 || std::ferror(trace.get()))
    throw ExploreError("output '" + trace_path.string() + "': write failed");
}

// summary.json's servo part: tick times, contact states, the collision queries' work.
void add_servo_summary(json& sj, RunRecord& rec, const config::Settings& s) {
  const ExploreSummary& sum = rec.sum;
  sj["ticks"] = sum.ticks;
  sj["servo_rate_hz"] = s.haptics.servo_rate_hz;
  sj["tick_ns"] = {
      {"p50", percentile(rec.tick_ns, 0.5)},
      {"p99", percentile(rec.tick_ns, 0.99)},
      {"p999", percentile(rec.tick_ns, 0.999)},
      {"max",
       rec.tick_ns.empty() ? 0.0 : static_cast<double>(*std::max_element(rec.tick_ns.begin(), rec.tick_ns.end()))}};
  sj["contact_ticks"] = {{"free", sum.free_ticks}, {"edge", sum.edge_ticks}, {"vertex", sum.vertex_ticks}};
  sj["max_force_n"] = sum.max_force_n;
  sj["query_budget_exhausted_ticks"] = rec.budget_exhausted;
  const double n = std::max<long>(1, sum.ticks);
  sj["per_tick"] = {{"queries_mean", rec.queries / n},
                    {"box_tests_mean", rec.box_tests / n},
                    {"boundary_section_mean", rec.section_sum / n},
                    {"boundary_section_max", rec.section_max},
                    {"iteration_limited_ticks", rec.iteration_limited}};
  sj["sticking_ticks"] = rec.sticking;
  sj["push_throughs"] = rec.pops;
  sj["device"] = {{"name", sum.device.name},
                  {"status", sum.device.status},
                  {"replies_missing", sum.device.replies_missing},
                  {"reconnects", sum.device.reconnects},
                  {"malformed_replies", sum.device.malformed}};
}

// summary.json's scene part: what the scene left out and why, in pipeline order, and its budgets and levels.
void add_scene_summary(json& sj, const ImageScene& is, const Scene& scene, const config::Settings& s) {
  sj["curves"] = scene.curve_count();
  sj["chains"] = {{"texture", is.chains_texture},
                  {"found", is.chains_found},
                  {"thin_line_pairs_merged", is.thin_line_pairs_merged},
                  {"after_thin_lines", is.chains_after_thin_lines},
                  {"gaps_closed", is.gaps_closed},
                  {"closed_by_gaps", is.chains_closed_by_gaps},
                  {"after_gaps", is.chains_after_gaps},
                  {"too_short", is.chains_too_short},
                  {"along_border", is.chains_along_border},
                  {"over_max_shapes", is.chains_over_max_shapes},
                  {"over_budget", is.chains_over_budget},
                  {"unbuildable", scene.skipped_curves()}};
  sj["shapes_budget"] = {{"max_shapes", s.vision.max_shapes}, {"kept", is.polylines.size()}};
  sj["segments_budget"] = {{"max_segments", s.vision.max_segments},
                           {"before", is.segments_before_budget},
                           {"after", is.segments_after_budget}};
  json segs = json::array();
  for (int l = 0; l < Scene::kMaxLevels; ++l) {
    bool any = false;
    for (std::size_t c = 0; c < scene.curve_count(); ++c) any = any || scene.curve(c).levels > l;
    if (!any) break;
    segs.push_back({{"level", l}, {"segments", scene.total_segments(l)}});
  }
  sj["segments_per_level"] = std::move(segs);
  sj["segments_in_use"] = scene.total_segments(s.haptics.level);
}

// summary.json's levels part: the mode, its changes and the ticks at each level id.
void add_level_summary(json& sj, const RunRecord& rec, const config::Settings& s) {
  json lt = json::array();
  for (int l = 0; l < kLevelIds; ++l) {
    if (rec.level_ticks[static_cast<std::size_t>(l)] == 0) continue;
    json e = {{"level", l}, {"ticks", rec.level_ticks[static_cast<std::size_t>(l)]}};
    const LevelChoice choice = LevelChoice::of_id(l);
    if (choice.kind != LevelChoice::Kind::Level) e["tolerance_m"] = kToleranceLadder_m[choice.index];
    if (choice.kind == LevelChoice::Kind::Cut) e["cut"] = true;
    lt.push_back(std::move(e));
  }
  sj["levels"] = {{"mode", s.haptics.level_mode},
                  {"changes", rec.level_changes},
                  {"ticks_waiting_for_a_safe_change", rec.level_waiting},
                  {"ticks_per_level", std::move(lt)}};
}

// summary.json's hand part: which hand, and the explorer's own counts; and the coverage it reached.
void add_hand_summary(json& sj, const ExploreOptions& o, const HandController& hand, RunRecord& rec,
                      const Scene& scene) {
  const bool known = o.hand == "raster" || o.hand == "explorer";
  sj["hand"] = {{"kind", known ? o.hand : std::string("file")}, {"seed", o.seed}};
  if (const auto* ex = dynamic_cast<const ExplorerHand*>(&hand)) {
    const ExplorerStats& st = ex->stats();
    sj["hand"]["explorer"] = {{"traces", st.traces},
                              {"traces_closed", st.traces_closed},
                              {"traces_lost", st.traces_lost},
                              {"traces_stalled", st.traces_stalled},
                              {"traces_timed_out", st.traces_timed_out},
                              {"traces_retraced", st.traces_retraced},
                              {"pops", st.pops},
                              {"pops_through", st.pops_through},
                              {"passes", st.passes},
                              {"plans", st.plans},
                              {"traced_m", st.traced_m},
                              {"move_s", st.move_s},
                              {"trace_s", st.trace_s},
                              {"pop_s", st.pop_s}};
  }
  const Coverage cov = rec.coverage.measure(scene);
  sj["coverage"] = {
      {"length_fraction", cov.length_fraction}, {"curves_touched", cov.curves_touched}, {"curves", cov.curves}};
}

// summary.json's picture part: the document's page, OCR, the detector, two tones and the build's times.
void add_picture_summary(json& sj, const ImageScene& is) {
  if (is.page > 0) {
    sj["document"] = {{"page", is.page},
                      {"pages", is.pages},
                      {"text_blocks", is.text_blocks.size()},
                      {"words_masked", is.text_words_masked},
                      {"dpi", is.render_dpi},
                      {"worker_ms", is.worker_ms},
                      {"worker_max_rss_kb", is.worker_max_rss_kb},
                      {"title", is.document_title}};
  }
  sj["ocr"] = {{"ran", is.ocr.ran},     {"why", is.ocr.why},
               {"words", is.ocr.words}, {"mean_confidence", is.ocr.mean_confidence},
               {"ms", is.ocr.ms},       {"worker_max_rss_kb", is.ocr.worker_max_rss_kb}};
  sj["canny_thresholds"] = {{"low", is.canny_low}, {"high", is.canny_high}};
  sj["detector"] = vision::detector_name(is.detector);
  sj["two_tone"] = {{"two_tone", is.tones.two_tone},
                    {"threshold", is.tones.threshold},
                    {"near_share", is.tones.near_share},
                    {"ink_width_px", is.tones.ink_width_px},
                    {"line_drawing", is.line_drawing}};
  sj["picture"] = {{"file_width_px", is.file_width_px},
                   {"file_height_px", is.file_height_px},
                   {"decode_scale", is.decode_scale},
                   {"width_px", is.width_px},
                   {"height_px", is.height_px}};
  sj["build_ms"] = {{"load", is.times.load_ms},
                    {"decode", is.times.decode_ms},
                    {"edges", is.times.edges_ms},
                    {"linking", is.times.linking_ms},
                    {"thin_lines", is.times.thin_lines_ms},
                    {"gaps", is.times.gaps_ms},
                    {"multires", is.times.multires_ms},
                    {"tree", is.times.tree_ms},
                    {"descriptors", is.times.descriptors_ms},
                    {"faces", is.times.faces_ms}};
}

// cues.csv and the WAV: the earcons on the trace's timeline (tick k sounds at t = k · period).
void write_earcons(const std::filesystem::path& out, const std::string& audio_out, const RunRecord& rec,
                   const config::Settings& s) {
  const double period_s = 1.0 / s.haptics.servo_rate_hz;
  std::string csv = "tick,t_s,kind,curve,speed_m_per_s,level\n";
  char line[160];
  for (const audio::CueEvent& e : rec.cues) {
    std::snprintf(line, sizeof line, "%lld,%.6f,%s,%d,%.6g,%d\n", static_cast<long long>(e.tick),
                  static_cast<double>(e.tick) * period_s, audio::cue_kind_name(e.kind), e.curve,
                  static_cast<double>(e.speed_m_per_s), e.level);
    csv += line;
  }
  write_text(out / "cues.csv", csv);
  const audio::MixerParams mp = audio_params_from(s).mixer;
  const std::vector<float> wav =
      audio::render_cue_timeline(rec.cues, period_s, static_cast<double>(rec.sum.ticks) * period_s, mp);
  audio::write_wav(audio_out, wav, audio::kSampleRateHz);
}

}  // namespace

ExploreSummary run_explore(const ExploreOptions& o) {
  if (!std::isfinite(o.duration_s) || o.duration_s > 24 * 3600.0) {
    throw ExploreError("--duration " + std::to_string(o.duration_s) + " s is outside (0, 86400] s");
  }
  const DeviceChoice device = parse_device_choice(o.device);
  const config::Settings s = explore_settings(o, device);
  const HandPath path = hand_path_of(o, s, device);
  const std::unique_ptr<HandController> hand = make_hand(o, s, path);
  const std::filesystem::path out = make_out_dir(o.out_dir);
  ImageScene is =
      o.source.empty() ? build_input_scene(o.image_path, o.page, s) : build_capture_scene(o.source, o.page, s, out);
  if (o.source.empty() && is.page == 0)  // a picture file's names, as the library takes them
    apply_names(is, names_file_for(o.image_path, names_dir(s)), std::filesystem::path(o.image_path).filename().string(),
                guesses_for(o.image_path, names_dir(s), guesses_wanted(o.image_path)));
  else
    add_guessed_regions(is);
  const Scene& scene = *is.scene;
  const double duration = o.duration_s > 0.0     ? o.duration_s
                          : o.hand == "explorer" ? hand->natural_duration_s()
                                                 : path.duration_s() + 0.5;
  check_audio_out(o.audio_out, duration);

  RunRecord rec;
  run_servo(scene, is, s, *hand, duration, device, rec);
  write_trace(out / "trace.csv", rec.rows);
  write_text(out / "scene.json", scene_json(is, s).dump() + "\n");
  json sj;
  add_servo_summary(sj, rec, s);
  add_scene_summary(sj, is, scene, s);
  add_level_summary(sj, rec, s);
  add_hand_summary(sj, o, *hand, rec, scene);
  add_picture_summary(sj, is);
  write_text(out / "summary.json", sj.dump(2) + "\n");
  write_overlay(out / "overlay.png", is, s.haptics.level, rec.proxy_path);
  if (!o.audio_out.empty()) write_earcons(out, o.audio_out, rec, s);
  return rec.sum;
}

}  // namespace hk::app
