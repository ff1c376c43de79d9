#pragma once
/// @file copy_desk.hpp
/// Take-home copies as the visitor asks for them (the Copy key, pressed twice): the picture shown, at the level in
/// use, in the visitor's language, laid out as a tactile graphic (copies/tactile_graphic.hpp), off the window
/// thread, and sent where staff chose ([copy] to): printed on the CUPS queue staff named ([copy] printer), saved in
/// a new folder on the visitor's USB stick (copies/stick_copy.hpp, through StickService::write_to_stick: FAT and
/// exFAT sticks only, mounted read-write for that write alone), or both; the outcome handed to the flow
/// (KioskFlow::copy_finished) and written in the log. At most [copy] per_day copies a day (counted from
/// local midnight, in memory: a restart counts afresh). Answers the flow's CopyEffects (kiosk_effects.hpp).
/// Window thread only, but for the worker it starts.

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "config/settings.hpp"
#include "copies/print_queue.hpp"
#include "copies/tactile_graphic.hpp"
#include "pictures/stick_service.hpp"
#include "visit/kiosk_effects.hpp"

namespace hk::app {

class KioskFlow;
class Stage;

/// The Copy key's work, on the stage.
class CopyDesk final : public CopyEffects {
 public:
  /// Sends a copy's PDF file to the printer, titled; what became of it (print_pdf's form).
  using Printer = std::function<PrintOutcome(const std::string& pdf_path, const std::string& title)>;
  /// What the visitor's language and words are (the catalogue in use): its BCP 47 tag and the key page's words.
  struct Language {
    std::string tag = "en";
    TactileWords words;
    std::string folder = "{title} (tactile copy)";  ///< the stick folder's name (catalogue: copy_folder)
  };
  using LanguageNow = std::function<Language()>;

  /// `settings` (the settings in use; read at each copy), `stage`, `language` and `stick` outlive the desk.
  /// `stick`: the kiosk's sticks (null: copies are never saved on one). `printer`: how copies reach paper; default
  /// print_pdf on [copy] printer.
  CopyDesk(const config::Settings& settings, const Stage& stage, LanguageNow language, StickService* stick = nullptr,
           Printer printer = {});
  ~CopyDesk() override;
  CopyDesk(const CopyDesk&) = delete;
  CopyDesk& operator=(const CopyDesk&) = delete;

  /// Copies are printed ([copy] to "printer" or "both", a queue named) or saved on sticks ("stick" or "both").
  bool copies_offered() const override;
  /// Copies go to sticks only and no stick is in.
  bool stick_missing() const override;
  /// [copy] per_day copies were started today (failed ones not counted).
  bool day_limit_reached() const override;
  /// Takes what is shown (a copy of its curves and names, on this thread) and lays it out, writes its PDF and
  /// prints it on a worker; false when nothing is shown that has curves, or a copy is still being made.
  bool start_copy() override;
  /// Every frame: a finished copy's outcome handed to `flow` (copy_finished).
  void poll(KioskFlow& flow, double now_s);
  /// A copy is being made.
  bool busy() const { return worker_.joinable(); }

 private:
  int today() const;    // local days since the epoch
  bool prints() const;  // [copy] to sends copies to a named printer
  bool saves() const;   // [copy] to sends copies to sticks, and there are sticks
  /// The worker's two routes, each filling its part of `r` (printed_line set by the caller).
  void print_copy(const TactileGraphic& g, BrailleGrade grade, const std::string& pdf, CopyReport& r);
  void save_copy(const TactileGraphic& g, BrailleGrade grade, const std::string& folder, CopyReport& r);

  const config::Settings& s_;
  const Stage& stage_;
  LanguageNow language_;
  StickService* stick_;
  Printer printer_;
  int day_ = -1, made_today_ = 0;
  std::mutex mutex_;
  std::optional<CopyReport> outcome_;  // under mutex_: what the worker made of the copy
  std::thread worker_;
};

}  // namespace hk::app
