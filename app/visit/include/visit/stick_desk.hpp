#pragma once
/// @file stick_desk.hpp
/// A USB stick as the visitor walks it: the stick service's news (a stick inserted, refused or taken out)
/// handed to the flow, its pages loaded off the window thread and put on the stage when the flow still wants
/// them, and what the stick could not give kept for the operator's panel. It answers the visitor's flow's
/// StickEffects (kiosk_effects.hpp). Window thread only.

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "audio/system.hpp"
#include "config/settings.hpp"
#include "pictures/picture_shelf.hpp"
#include "pictures/stick_service.hpp"
#include "visit/kiosk_effects.hpp"
#include "visit/stage.hpp"

namespace hk::app {

class KioskFlow;

/// A USB stick's documents on the stage. Not thread-safe: the window thread (the stick service's threads
/// are its own).
class StickDesk final : public StickEffects {
 public:
  /// Lines of stick_problems kept.
  static constexpr std::size_t kProblems = 200;

  /// Starts the stick service (stick_service.hpp: `events` null for no hot-plug; sticks mounted under
  /// `mount_root`). `stage`, `shelf` and `audio` outlive the desk.
  StickDesk(const config::Settings& settings, std::unique_ptr<sticks::BlockEventSource> events,
            const std::string& mount_root, Stage& stage, PictureShelf& shelf, const audio::AudioSystem& audio);

  /// Loads page `page` of document `document` of the stick the flow browses (the operator's level comes
  /// back; a library picture still being built is not wanted any more).
  void show_document(int document, int page) override;
  void forget_stick() override;

  /// Window thread, every frame: news of sticks and finished loads, handed to the flow.
  void poll(KioskFlow& flow, double now_s);
  /// Whether stick work (scan or load) may still bring news (scripted runs wait for it).
  bool busy() const { return busy_ || folder_ops_ > 0; }
  /// What the last stick could not give, for the operator's panel (a visitor hears only a count): one line a
  /// file, "'bad_crc.png': corrupt PNG header: …" for pictures and PDFs left out at the scan and "'manual.pdf'
  /// page 3: …" for pages that could not be built, then other entries left out (links, other files); at most
  /// kProblems (the log has them all). Kept until the next stick is inserted.
  const std::vector<std::string>& problems() const { return problems_; }
  /// A folder treated as an inserted USB stick / taken out again (documentation, tests).
  void insert_folder(const std::string& dir);
  void remove_folder();
  /// Page `page` of `document` of the stick browsed, built again with new settings and swapped in without a
  /// new announcement (nothing without a stick).
  void rebuild_page(int document, int page);
  /// New settings: pages built ahead with the old ones are dropped.
  void set_settings(const config::Settings& s) { service_.set_settings(s); }
  /// The longest side pages are shrunk to on the service's workers [px].
  void set_screen_picture_side_px(int px) { service_.set_screen_picture_side_px(px); }
  /// The stick service, for the operator's status and tests.
  const StickService& service() const { return service_; }
  /// The stick service, for writing copies onto the stick (CopyDesk).
  StickService& service() { return service_; }

 private:
  void inserted(StickNews& n, KioskFlow& flow, double now_s);
  void loaded(LoadedDocument& d, KioskFlow& flow, double now_s);
  void note_problem(std::string line);

  Stage& stage_;
  PictureShelf& shelf_;
  const audio::AudioSystem& audio_;
  int stick_ = 0;  // the stick the flow browses (StickNews::stick), 0 for none
  bool busy_ = false;
  int folder_ops_ = 0;                 // folders put in or taken out whose news has not come yet (one news each)
  int rebuild_id_ = 0;                 // a page re-requested by rebuild_page (shown without a new announcement)
  std::vector<std::string> problems_;  // problems()
  StickService service_;               // last: its threads stop first
};

}  // namespace hk::app
