#pragma once
/// @file copy_desk.hpp
/// Take-home copies as the visitor asks for them (the Copy key, pressed twice): the picture shown, at the level in
/// use, in the visitor's language, laid out as a tactile graphic (copies/tactile_graphic.hpp) and printed on the
/// CUPS queue staff named ([copy] printer), off the window thread; the outcome handed to the flow
/// (KioskFlow::copy_done, copy_failed) and written in the log. At most [copy] per_day copies a day (counted from
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
  };
  using LanguageNow = std::function<Language()>;

  /// `settings` (the settings in use; read at each copy), `stage` and `language` outlive the desk. `printer`:
  /// how copies reach paper; default print_pdf on [copy] printer.
  CopyDesk(const config::Settings& settings, const Stage& stage, LanguageNow language, Printer printer = {});
  ~CopyDesk() override;
  CopyDesk(const CopyDesk&) = delete;
  CopyDesk& operator=(const CopyDesk&) = delete;

  /// [copy] to is "printer" and a queue is named.
  bool copies_offered() const override;
  /// [copy] per_day copies were started today (failed ones not counted).
  bool day_limit_reached() const override;
  /// Takes what is shown (a copy of its curves and names, on this thread) and lays it out, writes its PDF and
  /// prints it on a worker; false when nothing is shown that has curves, or a copy is still being made.
  bool start_copy() override;
  /// Every frame: a finished copy's outcome handed to `flow` (copy_done with [copy] printed_line, or copy_failed).
  void poll(KioskFlow& flow, double now_s);
  /// A copy is being made.
  bool busy() const { return worker_.joinable(); }

 private:
  struct Outcome {
    bool ok = false;
    std::string error;
  };
  int today() const;  // local days since the epoch

  const config::Settings& s_;
  const Stage& stage_;
  LanguageNow language_;
  Printer printer_;
  int day_ = -1, made_today_ = 0;
  std::mutex mutex_;
  std::optional<Outcome> outcome_;  // under mutex_: what the worker made of the copy
  std::thread worker_;
};

}  // namespace hk::app
