// What the device and the screen show (stage.hpp).
#include "visit/stage.hpp"

#include "pictures/picture_names.hpp"

#include <spdlog/spdlog.h>

#include <cctype>
#include <map>

#include "haptics/tolerance_cut.hpp"
#include "pictures/picture_library.hpp"
#include "runtime/metrics.hpp"
#include "runtime/runtime_params.hpp"
#include "visit/describe.hpp"
#include "visit/read_aloud.hpp"

namespace hk::app {
namespace {

/// The language with the most letters in `letters` (by language, "" unknown); "" when unknown has the most.
std::string most_of(const std::map<std::string, std::size_t>& letters) {
  std::string best;
  std::size_t most = 0;
  for (const auto& [language, n] : letters)
    if (n > most) {
      most = n;
      best = language;
    }
  return best;
}

/// With level_mode = "cut", each curve's cut at each tolerance step (Shown::cut_segments and Shown::cuts).
void add_cuts(const Scene& sc, Shown& sh) {
  sh.cut_segments.assign(sc.curve_count(), std::vector<std::vector<SegmentRef>>(kToleranceSteps));
  sh.cuts.assign(sc.curve_count(), std::vector<std::vector<Vec2>>(kToleranceSteps));
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    for (int t = 0; t < kToleranceSteps; ++t) {
      std::vector<SegmentRef>& cut = sh.cut_segments[c][static_cast<std::size_t>(t)];
      tolerance_cut(sc, c, kToleranceLadder_m[t], &cut);
      sh.cuts[c][static_cast<std::size_t>(t)] = joined_cut_points(sc, c, cut.data(), cut.size());
    }
  }
}

}  // namespace

Stage::Stage(ServoStep& step, Voice& voice, const audio::AudioSystem& audio, TourDesk& tour, PictureShelf& shelf,
             const config::Settings& settings, Vec2 half_m)
    : step_(step),
      voice_(voice),
      audio_(audio),
      tour_(tour),
      shelf_(shelf),
      s_(settings),
      half_(half_m),
      level_(LevelChoice::of_id(settings.haptics.level)),
      auto_level_(settings.haptics.level_mode != "fixed") {}

void Stage::show_tutorial(TutorialShape shape) {
  shelf_.drop_want();  // a picture still being built is not wanted any more
  Shown sh;
  sh.polylines = {tutorial_polyline(shape, half_)};
  sh.descriptors = meaning::describe_shapes(sh.polylines, meaning::PictureColours{});
  static constexpr audio::MessageId kNames[] = {audio::MessageId::shape_square, audio::MessageId::shape_circle,
                                                audio::MessageId::shape_triangle};
  sh.notes.title = audio_.messages().text(kNames[static_cast<int>(shape)]);  // Where, Describe and the tour name it
  sh.notes.language = audio_.messages().language();
  publish(std::move(sh),
          std::make_unique<Scene>(Scene::build({tutorial_polyline(shape, half_)}, s_.haptics.max_levels)),
          -1 - static_cast<int>(shape));
  text_.cancel();
  text_news_.clear();
  source_ = {};
}

void Stage::show(ImageScene& is, int id, ShownSource source, PictureNotes notes, bool reading_said) {
  // A capture or a stick's page has no names file: the kiosk's own guesses name its parts.
  if (is.shape_region.size() != is.polylines.size() && notes.guesses) add_guessed_regions(is);
  Shown sh;
  sh.polylines = is.polylines;
  sh.descriptors = is.descriptors;
  sh.regions = is.regions;
  sh.shape_region = is.shape_region;
  sh.picture = is.picture;  // the pixels the scene was built from (a picture file decoded once, reduced)
  sh.image_path = is.image_path;
  sh.file_width_px = is.file_width_px > 0 ? is.file_width_px : is.picture.cols;
  sh.file_height_px = is.file_height_px > 0 ? is.file_height_px : is.picture.rows;
  sh.px_to_m = is.px_to_m;
  sh.text_blocks = is.text_blocks;
  sh.text_language = is.document_language;
  sh.faces_m = is.faces_m;
  sh.notes = std::move(notes);
  publish(std::move(sh), std::move(is.scene), id, text_block_regions(is.text_blocks));
  source_ = source;
  text_news_.clear();
  if (is.text_pending && is.with_text) {
    text_.start(id, [read = std::move(is.with_text), side_px = screen_side_px_](const TextRun& run) {
      ImageScene with_text = read(run);
      fit_picture(with_text, side_px);  // on the reader's worker, not the window thread
      return with_text;
    });
    text_since_s_ = -1.0;
    text_said_ = reading_said;
    text_heard_early_ = false;
  } else {
    text_.cancel();
  }
}

void Stage::publish(Shown sh, std::unique_ptr<Scene> scene, int id, std::vector<Aabb> text_boxes) {
  ++scenes_published_;
  const Scene& sc = *scene;
  sh.levels.resize(sc.curve_count());
  sh.closed.resize(sc.curve_count());
  for (std::size_t c = 0; c < sc.curve_count(); ++c) {
    sh.closed[c] = sc.curve(c).closed;
    for (int l = 0; l < sc.curve(c).levels; ++l) {
      const Vec2* p = sc.points(c, l);
      sh.levels[c].emplace_back(p, p + sc.curve(c).point_count[l]);
    }
  }
  sh.cut_segments.clear();
  sh.cuts.clear();
  if (s_.haptics.level_mode == "cut") add_cuts(sc, sh);
  ServoParams sp = servo_params_from(s_);
  sp.level = auto_level_ ? s_.haptics.level : level_.id();  // auto: where the policy starts
  sp.auto_level = auto_level_;
  auto bundle = std::make_unique<SceneBundle>(std::move(scene), sp);
  bundle->id = id;
  bundle->text_blocks_m = std::move(text_boxes);
  sh.scene = bundle->scene.get();
  shown_ = std::move(sh);
  const bool practice = id <= -1 && id >= -3;
  if (id != shown_id_ && !practice) kiosk_metrics().add(KioskCount::pictures_explored);  // not a rebuild of it
  shown_id_ = id;
  tour_.picture_changed(id, static_cast<int>(sc.curve_count()));
  step_.publish(std::move(bundle));
}

void Stage::poll_text(double now_s) {
  if (!text_news_.empty() && (text_news_id_ != shown_id_ || !audio_.speaking())) {
    if (text_news_id_ == shown_id_) voice_.say(text_news_);
    text_news_.clear();
  }
  if (!text_.pending()) return;
  if (text_.pending_id() != shown_id_) {  // another picture came meanwhile
    text_.cancel();
    return;
  }
  if (text_since_s_ < 0) text_since_s_ = now_s;
  if (std::optional<TextRead> read = text_.poll()) {
    text_arrived(*read);
    return;
  }
  if (!text_said_ && now_s - text_since_s_ > kTextWait_s && !audio_.speaking()) {
    text_said_ = true;
    voice_.say_brief(audio_.messages().text(audio::MessageId::text_reading));
  }
}

void Stage::text_arrived(TextRead& read) {
  ImageScene& is = read.scene;
  spdlog::info("text of scene {}: {}, {} words in {} blocks, read in {:.0f} ms", read.id, is.ocr.why, is.ocr.words,
               is.text_blocks.size(), read.wall_ms);
  kiosk_metrics().observe(KioskTiming::ocr, read.wall_ms / 1000.0);
  const audio::MessageCatalog& m = audio_.messages();
  text_news_id_ = read.id;
  const bool built = is.scene != nullptr;
  const bool said_reading = text_said_;
  if (built) show(is, read.id, source_, shown_.notes);  // the fade: no force step as the letters' curves go
  if (built && !is.text_blocks.empty() && text_heard_early_) {
    // Being read to the visitor as it came: nothing to announce.
  } else if (built && !is.text_blocks.empty()) {
    text_news_ = m.text(audio::MessageId::text_ready,
                        {{"description", describe_page(static_cast<int>(is.text_blocks.size()),
                                                       count_figures(is.polylines), audio_.messages())}});
  } else if (is.ocr.why.rfind("failed", 0) == 0 || !built) {
    text_news_ = m.text(audio::MessageId::text_unavailable);
  } else if (said_reading) {
    text_news_ = m.text(audio::MessageId::text_none);
  }
}

void Stage::set_names(std::vector<meaning::NamedRegion> regions, std::vector<int> shape_region) {
  if (shape_region.size() != shown_.polylines.size()) return;
  shown_.regions = std::move(regions);
  shown_.shape_region = std::move(shape_region);
  shown_.names_language.clear();  // made anew when next said
}

const PictureNames& Stage::names() const {
  const std::string& language = audio_.messages().language();
  if (shown_.names_language != language || shown_.names_language.empty()) {
    shown_.names = picture_names(shown_.regions, shown_.shape_region, shown_.polylines.size(), shown_.px_to_m,
                                 &shown_.polylines, audio_.messages());
    shown_.names_language = language;
  }
  return shown_.names;
}

ShownView Stage::view() const {
  said_notes_ = shown_notes();
  return {shown_.polylines,   shown_.descriptors, shown_.text_blocks, said_notes_,     half_,
          showing_tutorial(), source_.page > 0,   &names(),           &shown_.regions, shown_.px_to_m};
}

std::string Stage::where() {
  const ServoDisplayState& d = step_.display();
  // A practice shape: far and near explained with the first answer of the visit, not again.
  const bool explain = showing_tutorial() && !far_near_said_;
  far_near_said_ = far_near_said_ || explain;
  const std::string far_near = explain ? " " + audio_.messages().text(audio::MessageId::far_near) : std::string();
  return where_answer(view(), audio_.messages(), d.handle_m, d.scene_id == shown_id_ ? d.curve : -1) + far_near;
}

std::string Stage::shape_words(std::size_t curve) const { return app::shape_words(view(), curve, audio_.messages()); }

std::string Stage::describe() {
  // Its text still being read: said first, so the visitor knows more is coming.
  const std::string reading =
      text_.pending() ? audio_.messages().text(audio::MessageId::text_reading) + " " : std::string();
  return reading + describe_shown();
}

PictureNotes Stage::shown_notes() const {
  PictureNotes n = notes_in(shown_.notes, audio_.messages().language());
  if (n.language.empty() && n.from_sidecar) n.language = s_.kiosk.language;  // its top level: the default's
  return n;
}

PageText Stage::page_text() {
  PageText page;
  std::map<std::string, std::size_t> said_in;  // letters a language (OCR's), for a document that does not say
  const auto add = [&](const std::string& text, const std::string& language) {
    page.paragraphs.push_back(name_unclear_words(text, audio_.messages()));
    said_in[language] += text.size();
  };
  if (shown_.text_blocks.empty() && text_.pending() && text_.pending_id() == shown_id_) {
    // Its text still being read: the blocks read so far, more to come; the visitor hears them as they come,
    // so "The text is ready" is not said over them.
    for (const TextReader::Block& b : text_.blocks_so_far()) add(b.text, b.language);
    page.complete = false;
    text_heard_early_ = true;
  } else {
    for (const TextBlockM& b : shown_.text_blocks) add(b.text, b.language);
    if (const TextBlockM* b = text_block_at(shown_.text_blocks, step_.display().proxy_m))
      page.at_hand = static_cast<int>(b - shown_.text_blocks.data());
  }
  page.language = shown_.text_language.empty() ? most_of(said_in) : shown_.text_language;
  return page;
}

std::string Stage::describe_shown() {
  const ServoDisplayState& d = step_.display();
  return describe_answer(view(), audio_.messages(), d.handle_m, d.proxy_m);
}

bool Stage::change_level(int delta) {
  // From the level in use (chosen by hand speed in auto mode): the visitor's choice then holds until
  // another picture or page is asked for (reset_level) or the session ends. With a tolerance or cut step in use
  // (level_mode = "tolerance" or "cut") the keys move along the steps, so finer and coarser keep their order (and
  // their earcons) without comparing a step with a level.
  const std::optional<LevelChoice> next = LevelChoice::of_id(level()).stepped(delta, s_.haptics.max_levels);
  if (!next) return false;
  level_ = *next;
  auto_level_ = false;
  step_.request_level(level_.id());
  return true;
}

void Stage::reset_level(bool at_once) {
  level_ = LevelChoice::of_id(s_.haptics.level);
  auto_level_ = s_.haptics.level_mode != "fixed";
  if (at_once) step_.request_level(auto_level_ ? ServoStep::kAutoLevel : level_.id());
}

void Stage::new_visitor() {
  far_near_said_ = false;
  reset_level();
  tour_.new_visitor(shown_id_, shown_.scene ? static_cast<int>(shown_.scene->curve_count()) : 0);
}

TourPicture Stage::tour_picture() const {
  TourPicture p;
  p.scene = shown_.scene;
  p.id = shown_id_;
  p.described = shown_.polylines.size();
  p.words = [this](std::size_t curve) { return shape_words(curve); };
  const PictureNames& names = this->names();
  if (names.shape_name.empty() || showing_tutorial()) return p;
  p.name = [this](std::size_t curve) {
    const std::vector<std::string>& part = this->names().part_name;
    return curve < part.size() ? part[curve] : std::string();
  };
  for (const PictureNames::Part& part : names.parts)  // Guide leads to what staff named, not to guesses
    if (part.curve >= 0 && !part.guess) p.parts.push_back({part.name, static_cast<std::size_t>(part.curve)});
  return p;
}

}  // namespace hk::app
