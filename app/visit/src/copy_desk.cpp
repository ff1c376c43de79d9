// Take-home copies as the visitor asks for them (copy_desk.hpp).
#include "visit/copy_desk.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <ctime>
#include <filesystem>

#include "copies/tactile_output.hpp"
#include "copies/tactile_scene.hpp"
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

CopyDesk::CopyDesk(const config::Settings& settings, const Stage& stage, LanguageNow language, Printer printer)
    : s_(settings), stage_(stage), language_(std::move(language)), printer_(std::move(printer)) {
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

bool CopyDesk::copies_offered() const { return s_.copy.to == "printer" && !s_.copy.printer.empty(); }

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
  worker_ = std::thread([this, in = std::move(in), paper, words = lang.words, grade, pdf] {
    Outcome o;
    try {
      const TactileGraphic g = lay_out_tactile(in, paper, words);
      write_tactile(g, pdf, grade);
      const PrintOutcome p = printer_(pdf, in.title.empty() ? "haptic-kiosk copy" : in.title);
      o.ok = p.queued();
      o.error = p.error;
      if (o.ok) spdlog::info("copy: '{}' printed as job {}", in.title, p.job_id);
    } catch (const std::exception& e) {
      o.error = e.what();
    }
    std::error_code ec;
    std::filesystem::remove(pdf, ec);  // CUPS has its own copy once the job is queued
    std::lock_guard<std::mutex> lock(mutex_);
    outcome_ = o;
  });
  return true;
}

void CopyDesk::poll(KioskFlow& flow, double now_s) {
  std::optional<Outcome> o;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    o.swap(outcome_);
  }
  if (!o) return;
  worker_.join();
  if (o->ok) {
    flow.copy_done(s_.copy.printed_line, now_s);
    return;
  }
  --made_today_;  // not made: it does not count against the day
  spdlog::warn("copy: {}", o->error);
  flow.copy_failed(now_s);
}

}  // namespace hk::app
