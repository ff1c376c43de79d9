// Take-home copies as the visitor asks for them (copy_desk.hpp).
#include "visit/copy_desk.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <ctime>
#include <filesystem>

#include "copies/stick_copy.hpp"
#include "copies/tactile_output.hpp"
#include "copies/tactile_scene.hpp"
#include "runtime/event_log.hpp"
#include "visit/kiosk_flow.hpp"
#include "visit/stage.hpp"

namespace hk::app {
namespace {

/// The copy's title: the picture's own in the visitor's language, else its file's name.
std::string title_of(const Stage& stage) {
  const PictureNotes notes = stage.shown_notes();
  if (!notes.title.empty()) return notes.title;
  const std::string path = stage.shown().image_path;
  return path.empty() ? std::string() : std::filesystem::path(path).stem().string();
}

}  // namespace

CopyDesk::CopyDesk(const config::Settings& settings, const Stage& stage, LanguageNow language, StickService* stick,
                   Printer printer)
    : s_(settings), stage_(stage), language_(std::move(language)), stick_(stick), printer_(std::move(printer)) {
  if (!printer_)
    printer_ = [this](const std::string& pdf, const std::string& title) {
      return print_pdf(s_.copy.printer, pdf, title);
    };
}

CopyDesk::~CopyDesk() {
  if (worker_.joinable()) worker_.join();
}

int CopyDesk::today() const {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  if (localtime_r(&now, &local) == nullptr) return 0;
  return local.tm_year * 400 + local.tm_yday;
}

bool CopyDesk::prints() const { return (s_.copy.to == "printer" || s_.copy.to == "both") && !s_.copy.printer.empty(); }

bool CopyDesk::saves() const { return (s_.copy.to == "stick" || s_.copy.to == "both") && stick_ != nullptr; }

bool CopyDesk::copies_offered() const { return prints() || saves(); }

bool CopyDesk::stick_missing() const { return saves() && !prints() && !stick_->stick_in(); }

bool CopyDesk::day_limit_reached() const { return day_ == today() && made_today_ >= s_.copy.per_day; }

bool CopyDesk::start_copy() {
  const Shown& shown = stage_.shown();
  if (busy() || shown.scene == nullptr || shown.scene->curve_count() == 0 || shown.image_path.empty()) return false;
  const Language lang = language_ ? language_() : Language{};
  const Paper paper = parse_paper(s_.copy.paper).value_or(Paper::a4);
  const BrailleGrade grade = s_.copy.braille_grade == 1 ? BrailleGrade::one : BrailleGrade::two;
  // What is shown is copied here, on the window thread: the worker never reads the stage.
  const SceneToCopy what{shown.scene,   &shown.regions,     &shown.shape_region,
                         shown.px_to_m, shown.picture.cols, shown.picture.rows};
  TactileInput in = tactile_input_of(what, stage_.level(), paper, lang.tag, title_of(stage_), grade);
  if (day_ != today()) {
    day_ = today();
    made_today_ = 0;
  }
  ++made_today_;
  const std::string pdf = (std::filesystem::temp_directory_path() / ("haptic-kiosk-copy-" + std::to_string(::getpid()) +
                                                                     "-" + std::to_string(made_today_) + ".pdf"))
                              .string();
  // Where it goes is decided here, on the window thread: the worker never reads the settings.
  const bool to_printer = prints();
  const bool to_stick = saves() && stick_->stick_in();  // "both" without a stick: printed only
  CopyReport start;
  start.printed_line = s_.copy.printed_line;
  worker_ = std::thread([this, in = std::move(in), paper, words = lang.words, folder = lang.folder, grade, pdf,
                         to_printer, to_stick, r = start]() mutable {
    try {
      const TactileGraphic g = lay_out_tactile(in, paper, words);
      if (to_printer) print_copy(g, grade, pdf, r);
      if (to_stick) save_copy(g, grade, folder, r);
    } catch (const std::exception& e) {  // the layout itself failed: neither route has a copy
      spdlog::warn("copy: '{}': {}", in.title, e.what());
      if (to_printer) r.printed = CopyReport::Route::Failed;
      if (to_stick) r.saved = CopyReport::Route::Failed;
    }
    if (r.printed == CopyReport::Route::NotAsked && r.saved == CopyReport::Route::NotAsked)
      r.printed = CopyReport::Route::Failed;  // settings changed under the copy: say sorry rather than nothing
    const std::lock_guard<std::mutex> lock(mutex_);
    outcome_ = r;
  });
  return true;
}

void CopyDesk::print_copy(const TactileGraphic& g, BrailleGrade grade, const std::string& pdf, CopyReport& r) {
  r.printed = CopyReport::Route::Failed;
  try {
    write_tactile(g, pdf, grade);
    const PrintOutcome p = printer_(pdf, g.title.empty() ? "haptic-kiosk copy" : g.title);
    if (p.queued()) {
      r.printed = CopyReport::Route::Done;
      spdlog::info("copy: '{}' printed as job {}", g.title, p.job_id);
    } else {
      spdlog::warn("copy: '{}' not printed: {}", g.title, p.error);
    }
  } catch (const std::exception& e) {
    spdlog::warn("copy: '{}' not printed: {}", g.title, e.what());
  }
  std::error_code ec;
  std::filesystem::remove(pdf, ec);  // CUPS has its own copy once the job is queued
}

void CopyDesk::save_copy(const TactileGraphic& g, BrailleGrade grade, const std::string& folder, CopyReport& r) {
  using Kind = StickWriteOutcome::Kind;
  r.saved = CopyReport::Route::Failed;
  SavedCopy saved;
  try {
    const StickWriteOutcome o =
        stick_->write_to_stick([&](const std::string& top) { saved = save_copy_folder(g, top, folder, grade); }).get();
    switch (o.kind) {
      case Kind::Written:
        r.saved = CopyReport::Route::Done;
        break;
      case Kind::NoStick:
        r.saved = CopyReport::Route::NoStick;
        break;
      case Kind::WriteProtected:
        r.saved = CopyReport::Route::WriteProtected;
        break;
      case Kind::Format:
        r.saved = CopyReport::Route::Format;
        break;
      case Kind::Failed:
        break;
    }
    if (!o.error.empty()) spdlog::warn("copy: '{}' not saved on the stick: {}", g.title, o.error);
  } catch (const CopyNoRoomError& e) {
    r.saved = CopyReport::Route::Full;
    spdlog::warn("copy: '{}' not saved on the stick: {}", g.title, e.what());
  } catch (const std::exception& e) {
    spdlog::warn("copy: '{}' not saved on the stick: {}", g.title, e.what());
  }
  if (r.saved == CopyReport::Route::Done) {
    r.folder = saved.folder;
    spdlog::info("copy: '{}' saved on the stick in '{}' ({} files)", g.title, saved.folder, saved.files.size());
  }
}

void CopyDesk::poll(KioskFlow& flow, double now_s) {
  std::optional<CopyReport> r;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    r.swap(outcome_);
  }
  if (!r) return;
  worker_.join();
  if (r->nothing_made()) --made_today_;  // not made: it does not count against the day
  const bool printed = r->printed == CopyReport::Route::Done, saved = r->saved == CopyReport::Route::Done;
  if (r->nothing_made())
    log_event(KioskEvent::copy_failed, spdlog::level::warn, "copy: neither printed nor saved (why is logged above)");
  else
    log_event(KioskEvent::copy_made, spdlog::level::info,
              std::string("copy: ") + (printed && saved ? "printed and saved on a stick"
                                       : printed        ? "printed"
                                                        : "saved on a stick"));
  flow.copy_finished(*r, now_s);
}

}  // namespace hk::app
