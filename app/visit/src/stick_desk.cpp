// A USB stick as the visitor walks it (stick_desk.hpp).
#include "visit/stick_desk.hpp"

#include "runtime/event_log.hpp"

#include <algorithm>

#include "visit/describe.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

StickDesk::StickDesk(const config::Settings& settings, std::unique_ptr<sticks::BlockEventSource> events,
                     const std::string& mount_root, Stage& stage, PictureShelf& shelf, const audio::AudioSystem& audio)
    : stage_(stage), shelf_(shelf), audio_(audio), service_(settings, std::move(events), mount_root) {}

void StickDesk::show_document(int document, int page) {
  stage_.reset_level();  // a level the visitor chose holds for one page
  shelf_.drop_want();    // the stick's page, not a library picture still being built
  service_.load(stick_, document, page);
}

void StickDesk::forget_stick() {
  service_.forget();
  stick_ = 0;
  busy_ = false;  // a page still being built for the forgotten stick is dropped when it comes
  rebuild_id_ = 0;
}

void StickDesk::poll(KioskFlow& flow, double now_s) {
  for (StickNews& n : service_.poll_news()) {
    folder_ops_ = std::max(0, folder_ops_ - 1);
    if (n.kind == StickNews::Kind::Inserted) {
      inserted(n, flow, now_s);
    } else if (n.kind == StickNews::Kind::Refused) {
      log_event(KioskEvent::stick_refused, spdlog::level::warn, "stick: refused: " + n.reason);
      busy_ = false;
      flow.stick_refused(n.reason, now_s);
    } else {
      stick_ = 0;
      busy_ = false;
      rebuild_id_ = 0;
      flow.stick_removed(now_s);
    }
  }
  for (LoadedDocument& d : service_.poll_loaded()) {
    if (d.stick != stick_) continue;  // a stick taken out or forgotten meanwhile
    loaded(d, flow, now_s);
  }
  if (flow.view().loading) busy_ = true;
}

void StickDesk::inserted(StickNews& n, KioskFlow& flow, double now_s) {
  stick_ = n.stick;
  std::vector<StickEntry> entries;
  for (const ListedDocument& d : n.documents)
    entries.push_back({d.doc.display_name, d.doc.kind == vision::DocumentKind::Pdf, d.pages, d.title, d.pages_in_file});
  busy_ = !entries.empty();
  problems_.clear();
  // Pictures and PDFs first: what the visitor was told of; then the rest left out.
  for (const bool documents : {true, false})
    for (const vision::RefusedEntry& r : n.refused)
      if (r.document == documents) note_problem("'" + r.path + "': " + r.reason);
  log_event(
      KioskEvent::stick_inserted, spdlog::level::info,
      fmt::format("stick: {} documents, {} left out, read in {:.0f} ms", entries.size(), n.refused_entries, n.scan_ms));
  flow.stick_inserted(entries, now_s, n.unreadable_documents);
}

void StickDesk::loaded(LoadedDocument& d, KioskFlow& flow, double now_s) {
  const int id = page_id(d.document, d.page);
  if (rebuild_id_ == id && !flow.view().loading) {
    // The page shown, rebuilt with new settings (rebuild_page): swapped in without a new announcement.
    rebuild_id_ = 0;
    if (d.scene) stage_.show(*d.scene, id, stage_.source(), {});
    busy_ = false;
    return;
  }
  if (!flow.view().awaits_document(d.document, d.page)) return;  // superseded by a later Next or Previous: never felt
  DocumentResult r;
  r.document = d.document;
  r.page = d.page;
  if (d.scene) {
    ImageScene& is = *d.scene;
    r.ok = true;
    // A page, or a picture of one (its text read): blocks of text and figures; its text still being read:
    // said so at once; else shapes.
    const bool said_reading = is.text_pending && is.text_likely;
    r.description =
        said_reading ? audio_.messages().text(audio::MessageId::text_reading)
        : is.page > 0 || !is.text_blocks.empty()
            ? describe_page(static_cast<int>(is.text_blocks.size()), count_figures(is.polylines), audio_.messages())
            : describe_shapes(static_cast<int>(is.scene->curve_count()), audio_.messages());
    stage_.show(is, id, ShownSource{-1, d.document, is.page}, {}, said_reading);
  } else {
    r.reason = d.reason;
    const std::span<const StickEntry> docs = flow.view().stick_documents;
    const std::string name = d.document >= 0 && d.document < static_cast<int>(docs.size())
                                 ? docs[static_cast<std::size_t>(d.document)].name
                                 : "?";
    note_problem("'" + name + "' page " + std::to_string(d.page) + ": " + d.reason);
  }
  busy_ = false;
  flow.document_ready(r, now_s);
}

void StickDesk::note_problem(std::string line) {
  if (problems_.size() < kProblems) problems_.push_back(std::move(line));
}

void StickDesk::insert_folder(const std::string& dir) {
  busy_ = true;
  ++folder_ops_;
  service_.insert_folder(dir);
}

void StickDesk::remove_folder() {
  busy_ = true;  // until the news of the removal arrives
  ++folder_ops_;
  service_.remove_folder();
}

void StickDesk::rebuild_page(int document, int page) {
  if (stick_ == 0) return;
  rebuild_id_ = page_id(document, page);
  busy_ = true;
  service_.load(stick_, document, page);
}

}  // namespace hk::app
