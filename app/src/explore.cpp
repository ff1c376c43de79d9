// Headless explore run: image → scene → simulated pantograph + model hand → servo ticks → files.
#include "explore.hpp"

#include <array>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include "audio/mixer.hpp"
#include "audio/wav.hpp"
#include "capture.hpp"
#include "config/load.hpp"
#include "coverage.hpp"
#include "cue_tracker.hpp"
#include "documents.hpp"
#include "haptics/tolerance_cut.hpp"
#include "haptics/explorer_hand.hpp"
#include "haptics/hand_path.hpp"
#include "haptics/servo.hpp"
#include "image_scene.hpp"
#include "simulation.hpp"

namespace hk::app {
namespace {

using json = nlohmann::json;

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f << text;
  f.close();
  if (!f) throw ExploreError("output '" + p.string() + "': cannot write the file");
}

json scene_json(const ImageScene& is, const config::Settings& s) {
  json j;
  j["image"] = {{"path", is.image_path}, {"width_px", is.width_px}, {"height_px", is.height_px}};
  j["px_to_m"] = {{"scale", is.px_to_m.scale_m_per_px}, {"offset_x_m", is.px_to_m.offset_x_m}, {"offset_y_m", is.px_to_m.offset_y_m}};
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
      levels.push_back({{"level", l}, {"points_m", std::move(pts)}, {"max_error_m", ci.max_error_m[l]},
                        {"max_box_half_width_m", ci.max_box_half_width_m[l]}, {"max_error_bound_m", ci.max_error_bound_m[l]}});
    }
    curves.push_back({{"id", c}, {"closed", ci.closed}, {"levels", std::move(levels)}});
  }
  j["curves"] = std::move(curves);
  if (is.page > 0) {
    j["page"] = is.page;
    j["pages"] = is.pages;
  }
  if (is.page > 0 || !is.text_blocks.empty()) {  // a page with text: its text is spoken, not felt
    json blocks = json::array();
    for (const TextBlockM& b : is.text_blocks) {
      blocks.push_back({{"id", b.id}, {"bbox_m", {b.lo_m.x, b.lo_m.y, b.hi_m.x, b.hi_m.y}}, {"text", b.text}, {"source", b.source},
                        {"confidence", b.confidence}});
    }
    j["text_blocks"] = std::move(blocks);
  }
  return j;
}

cv::Point2d to_px(const vision::PxToM& m, Vec2 q) { return {m.u_px(q.x), m.v_px(q.y)}; }

void write_overlay(const std::filesystem::path& out, const ImageScene& is, int level, const std::vector<Vec2>& proxy_path) {
  cv::Mat img = is.picture.empty() ? cv::imread(is.image_path, cv::IMREAD_COLOR) : is.picture.clone();
  if (img.empty()) throw ExploreError("image '" + is.image_path + "': could not be read again for the overlay");
  // Dim the picture so the drawn curves stand out; draw at 4x sub-pixel precision.
  img = img * 0.55;
  const int thick = std::max(1, static_cast<int>(std::lround(std::max(img.cols, img.rows) / 400.0)));
  constexpr int kShift = 2;
  auto fixed = [&](cv::Point2d p) { return cv::Point(static_cast<int>(std::lround(p.x * 4)), static_cast<int>(std::lround(p.y * 4))); };
  const Scene& sc = *is.scene;
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    const int l = sc.clamp_level(c, level);
    std::vector<cv::Point> pts;
    if (is_cut_level(level)) {  // a cut step: the cut's joined polyline, what the walls were
      std::vector<SegmentRef> cut;
      tolerance_cut(sc, c, kToleranceLadder_m[tolerance_step_of(level)], &cut);
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
  if (path.size() > 1) cv::polylines(img, path, false, cv::Scalar(255, 120, 40), std::max(1, thick / 2), cv::LINE_AA, kShift);
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
ImageScene build_capture_scene(const std::string& spec_text, int page, const config::Settings& s, const std::filesystem::path& out) {
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
    if (page > 0) throw ExploreError("--page " + std::to_string(page) + ": '" + path + "' is not a PDF (pages are for PDF documents)");
    return build_image_scene(path, s);
  }
  return build_pdf_page_scene(vision::read_input_file(path, s.stick.max_file_bytes), path, page > 0 ? page : 1, s);
}

ExploreSummary run_explore(const ExploreOptions& o) {
  config::Settings s = o.config_path.empty() ? config::Settings{} : config::load_settings(o.config_path);
  if (!std::isfinite(o.duration_s) || o.duration_s > 24 * 3600.0) {
    throw ExploreError("--duration " + std::to_string(o.duration_s) + " s is outside (0, 86400] s");
  }
  const DeviceChoice device = parse_device_choice(o.device);
  if (device.kind == DeviceChoice::Kind::HaplyEmulator) {
    // The emulated board is a Haply: its profile's forces and stiffness, as the kiosk would take it.
    std::vector<std::string> notes;
    s = settings_for_board(s, &notes);
    for (const std::string& n : notes) spdlog::warn("device: {}", n);
  }
  const bool explorer = o.hand == "explorer";
  if (explorer && device.kind == DeviceChoice::Kind::HaplyEmulator) {
    throw ExploreError("--hand explorer: the explorer needs the device's force each tick, which only --device sim gives");
  }
  // Read the hand before the (slower) image so a bad hand file fails fast.
  const HandPath path = o.hand == "raster" || explorer
                            ? raster_path(s.workspace.width_m, s.workspace.height_m, s.hand.raster_spacing_m, s.hand.raster_speed_m_per_s)
                            : load_hand_csv(o.hand);
  std::unique_ptr<HandController> hand;
  if (explorer) {
    hand = std::make_unique<ExplorerHand>(explorer_params_from(s, o.seed));
  } else {
    hand = std::make_unique<PathHand>(path, s.hand.max_force_n);
  }
  std::error_code ec;
  std::filesystem::create_directories(o.out_dir, ec);
  if (ec || !std::filesystem::is_directory(o.out_dir)) {
    throw ExploreError("output folder '" + o.out_dir + "': cannot create it (" + ec.message() + ")");
  }
  const std::filesystem::path out(o.out_dir);

  ImageScene is = o.source.empty() ? build_input_scene(o.image_path, o.page, s) : build_capture_scene(o.source, o.page, s, out);
  const Scene& scene = *is.scene;

  const double duration = o.duration_s > 0.0 ? o.duration_s : explorer ? hand->natural_duration_s() : path.duration_s() + 0.5;
  if (!o.audio_out.empty()) {
    const std::filesystem::path a(o.audio_out);
    std::string ext = a.extension().string();
    for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (ext != ".wav") throw ExploreError("--audio-out '" + o.audio_out + "': must name a .wav file");
    const std::filesystem::path parent = a.has_parent_path() ? a.parent_path() : std::filesystem::path(".");
    if (!std::filesystem::is_directory(parent)) {
      throw ExploreError("--audio-out '" + o.audio_out + "': folder '" + parent.string() + "' does not exist");
    }
    if (duration > 3600.0) {
      throw ExploreError("--audio-out '" + o.audio_out + "': a run of " + std::to_string(duration) + " s is over the audio limit of 3600 s");
    }
  }
  const std::filesystem::path trace_path = out / "trace.csv";
  std::unique_ptr<FILE, int (*)(FILE*)> trace(std::fopen(trace_path.c_str(), "w"), &std::fclose);
  if (!trace) throw ExploreError("output '" + trace_path.string() + "': cannot open for writing");
  static char buffer[1 << 16];
  std::setvbuf(trace.get(), buffer, _IOFBF, sizeof buffer);
  std::fputs("t_s,handle_x_m,handle_y_m,proxy_x_m,proxy_y_m,force_x_n,force_y_n,contact,curve,level,tick_ns,pop\n", trace.get());

  struct Row {
    double t_s;
    Vec2 handle_m, proxy_m, force_n;
    int contact, curve, level;
    std::int64_t tick_ns;
    int pop;
  };
  std::vector<Row> rows;
  rows.reserve(static_cast<std::size_t>(std::ceil(duration * s.haptics.servo_rate_hz)) + 1);
  ExploreSummary sum;
  sum.curves = scene.curve_count();
  std::vector<std::int64_t> tick_ns;
  std::vector<Vec2> proxy_path;
  long budget_exhausted = 0;
  double queries = 0, box_tests = 0, section_sum = 0;
  long section_max = 0, iteration_limited = 0;
  long level_changes = 0, level_waiting = 0, sticking = 0, pops = 0;
  std::array<long, kLevelIds> level_ticks{};  // per level id (levels and tolerance steps)
  const CueTrackerParams ctp = cue_params_from(s);
  audio::SpscRing<audio::CueEvent> cue_ring(64);  // the step's earcons, drained after every tick
  RunOptions run;
  run.device = device;
  run.report = &sum.device;
  run.cues = &cue_ring;
  run.text_blocks_m = text_block_regions(is.text_blocks);
  std::vector<audio::CueEvent> cues;
  CoverageMeter coverage(0.001);
  run_simulation(scene, s, *hand, duration, [&](const TickRecord& r, const ServoOutput& so) {
    const ContactOutput& c = so.contact;
    for (audio::CueEvent e; cue_ring.try_pop(e);) cues.push_back(e);
    const int state = static_cast<int>(c.state);
    const int curve = c.state == ContactState::Free ? -1 : c.constraint[0].curve;
    // Rows are kept in memory and formatted after the run: printf between ticks would evict the
    // servo's data from the caches and inflate the tick times we measure.
    const int pop = (c.events & kEventPopThrough) != 0;
    rows.push_back({r.t_s, r.handle_m, c.proxy_m, so.force_n, state, curve, c.level, r.tick_ns, pop});
    pops += pop;
    tick_ns.push_back(r.tick_ns);
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
  }, run);
  for (const Row& w : rows) {
    std::fprintf(trace.get(), "%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%d,%lld,%d\n", w.t_s, w.handle_m.x, w.handle_m.y, w.proxy_m.x,
                 w.proxy_m.y, w.force_n.x, w.force_n.y, w.contact, w.curve, w.level, static_cast<long long>(w.tick_ns), w.pop);
  }
  if (std::fflush(trace.get()) != 0 || std::ferror(trace.get())) throw ExploreError("output '" + trace_path.string() + "': write failed");
  trace.reset();

  write_text(out / "scene.json", scene_json(is, s).dump() + "\n");
  json sj;
  sj["ticks"] = sum.ticks;
  sj["servo_rate_hz"] = s.haptics.servo_rate_hz;
  sj["tick_ns"] = {{"p50", percentile(tick_ns, 0.5)}, {"p99", percentile(tick_ns, 0.99)}, {"p999", percentile(tick_ns, 0.999)},
                   {"max", tick_ns.empty() ? 0.0 : static_cast<double>(*std::max_element(tick_ns.begin(), tick_ns.end()))}};
  sj["contact_ticks"] = {{"free", sum.free_ticks}, {"edge", sum.edge_ticks}, {"vertex", sum.vertex_ticks}};
  sj["max_force_n"] = sum.max_force_n;
  sj["query_budget_exhausted_ticks"] = budget_exhausted;
  const double n = std::max<long>(1, sum.ticks);
  sj["per_tick"] = {{"queries_mean", queries / n}, {"box_tests_mean", box_tests / n}, {"boundary_section_mean", section_sum / n},
                    {"boundary_section_max", section_max}, {"iteration_limited_ticks", iteration_limited}};
  sj["curves"] = scene.curve_count();
  // What the scene left out and why (issue 6, item 4), in pipeline order.
  sj["chains"] = {{"texture", is.chains_texture}, {"found", is.chains_found}, {"thin_line_pairs_merged", is.thin_line_pairs_merged},
                  {"after_thin_lines", is.chains_after_thin_lines}, {"gaps_closed", is.gaps_closed},
                  {"closed_by_gaps", is.chains_closed_by_gaps}, {"after_gaps", is.chains_after_gaps}, {"too_short", is.chains_too_short},
                  {"along_border", is.chains_along_border}, {"over_max_shapes", is.chains_over_max_shapes},
                  {"over_budget", is.chains_over_budget}, {"unbuildable", scene.skipped_curves()}};
  sj["shapes_budget"] = {{"max_shapes", s.vision.max_shapes}, {"kept", is.polylines.size()}};
  sj["segments_budget"] = {{"max_segments", s.vision.max_segments}, {"before", is.segments_before_budget}, {"after", is.segments_after_budget}};
  json segs = json::array();
  for (int l = 0; l < Scene::kMaxLevels; ++l) {
    bool any = false;
    for (std::size_t c = 0; c < scene.curve_count(); ++c) any = any || scene.curve(c).levels > l;
    if (!any) break;
    segs.push_back({{"level", l}, {"segments", scene.total_segments(l)}});
  }
  sj["segments_per_level"] = std::move(segs);
  json lt = json::array();
  for (int l = 0; l < kLevelIds; ++l) {
    if (level_ticks[static_cast<std::size_t>(l)] == 0) continue;
    json e = {{"level", l}, {"ticks", level_ticks[static_cast<std::size_t>(l)]}};
    if (tolerance_step_of(l) >= 0) e["tolerance_m"] = kToleranceLadder_m[tolerance_step_of(l)];  // a tolerance or cut step's id
    if (is_cut_level(l)) e["cut"] = true;
    lt.push_back(std::move(e));
  }
  sj["levels"] = {{"mode", s.haptics.level_mode}, {"changes", level_changes}, {"ticks_waiting_for_a_safe_change", level_waiting},
                  {"ticks_per_level", std::move(lt)}};
  sj["sticking_ticks"] = sticking;
  sj["push_throughs"] = pops;
  const Coverage cov = coverage.measure(scene);
  sj["hand"] = {{"kind", o.hand == "raster" || explorer ? o.hand : std::string("file")}, {"seed", o.seed}};
  if (const auto* ex = dynamic_cast<const ExplorerHand*>(hand.get())) {
    const ExplorerStats& st = ex->stats();
    sj["hand"]["explorer"] = {{"traces", st.traces}, {"traces_closed", st.traces_closed}, {"traces_lost", st.traces_lost},
                              {"traces_stalled", st.traces_stalled}, {"traces_timed_out", st.traces_timed_out},
                              {"traces_retraced", st.traces_retraced}, {"pops", st.pops}, {"pops_through", st.pops_through},
                              {"passes", st.passes}, {"plans", st.plans}, {"traced_m", st.traced_m},
                              {"move_s", st.move_s}, {"trace_s", st.trace_s}, {"pop_s", st.pop_s}};
  }
  sj["coverage"] = {{"length_fraction", cov.length_fraction}, {"curves_touched", cov.curves_touched}, {"curves", cov.curves}};
  sj["device"] = {{"name", sum.device.name}, {"status", sum.device.status}, {"replies_missing", sum.device.replies_missing},
                  {"reconnects", sum.device.reconnects}, {"malformed_replies", sum.device.malformed}};
  if (is.page > 0) {
    sj["document"] = {{"page", is.page}, {"pages", is.pages}, {"text_blocks", is.text_blocks.size()}, {"words_masked", is.text_words_masked},
                      {"dpi", is.render_dpi}, {"worker_ms", is.worker_ms}, {"worker_max_rss_kb", is.worker_max_rss_kb},
                      {"title", is.document_title}};
  }
  sj["ocr"] = {{"ran", is.ocr.ran}, {"why", is.ocr.why}, {"words", is.ocr.words}, {"mean_confidence", is.ocr.mean_confidence},
               {"ms", is.ocr.ms}, {"worker_max_rss_kb", is.ocr.worker_max_rss_kb}};
  sj["segments_in_use"] = scene.total_segments(s.haptics.level);
  sj["canny_thresholds"] = {{"low", is.canny_low}, {"high", is.canny_high}};
  sj["detector"] = vision::detector_name(is.detector);
  sj["two_tone"] = {{"two_tone", is.tones.two_tone}, {"threshold", is.tones.threshold}, {"near_share", is.tones.near_share}, {"ink_width_px", is.tones.ink_width_px}, {"line_drawing", is.line_drawing}};
  sj["build_ms"] = {{"load", is.times.load_ms}, {"edges", is.times.edges_ms}, {"linking", is.times.linking_ms}, {"thin_lines", is.times.thin_lines_ms}, {"gaps", is.times.gaps_ms},
                    {"multires", is.times.multires_ms}, {"tree", is.times.tree_ms}};
  write_text(out / "summary.json", sj.dump(2) + "\n");
  write_overlay(out / "overlay.png", is, s.haptics.level, proxy_path);
  sum.cues = cues.size();
  if (!o.audio_out.empty()) {
    // The earcons on the trace's timeline: tick k sounds at t = k · period (issue 4, item 5).
    std::string csv = "tick,t_s,kind,curve,speed_m_per_s,level\n";
    char line[160];
    for (const audio::CueEvent& e : cues) {
      std::snprintf(line, sizeof line, "%lld,%.6f,%s,%d,%.6g,%d\n", static_cast<long long>(e.tick),
                    static_cast<double>(e.tick) * ctp.period_s, audio::cue_kind_name(e.kind), e.curve,
                    static_cast<double>(e.speed_m_per_s), e.level);
      csv += line;
    }
    write_text(out / "cues.csv", csv);
    audio::MixerParams mp;
    mp.earcons.gain = s.audio.earcon_gain;
    mp.duck_db = s.audio.duck_db;
    const std::vector<float> wav = audio::render_cue_timeline(cues, ctp.period_s, static_cast<double>(sum.ticks) * ctp.period_s, mp);
    audio::write_wav(o.audio_out, wav, audio::kSampleRateHz);
  }
  return sum;
}

}  // namespace hk::app
