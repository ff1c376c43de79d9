// The visitor's flow: the news the window layer reports (kiosk_flow.hpp): a camera capture's advice and
// outcome, USB sticks inserted, refused and removed, stick pages and library pictures that have come.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "pictures/stick_pages.hpp"
#include "visit/kiosk_flow.hpp"

namespace hk::app {

using audio::MessageId;

// ---- the camera --------------------------------------------------------------------------------------

void KioskFlow::capture_advice(MessageId advice, double now_s) {
  if (!v_.capturing) return;
  activity(now_s);
  say(advice);
}

void KioskFlow::capture_done(int shapes, double now_s) {
  guarded("a camera capture", [&] { capture_done_now(shapes, now_s); });
}

void KioskFlow::capture_done_now(int shapes, double now_s) {
  if (!v_.capturing) return;
  v_.capturing = false;
  activity(now_s);
  v_.state = KioskState::Picture;
  v_.captured = true;
  if (shapes == 0) {
    say(MessageId::captured_empty);
  } else {
    fx_.speech.say(counted(MessageId::captured, shapes));
  }
}

void KioskFlow::capture_failed(bool timeout, double now_s) {
  if (!v_.capturing) return;
  v_.capturing = false;
  v_.last_activity_s = now_s;
  say(timeout ? MessageId::capture_timeout : MessageId::capture_failed);
}

// ---- USB sticks --------------------------------------------------------------------------------------

std::string KioskFlow::stick_summary() const {
  // The {summary} of stick_inserted, from the catalogue's summary_* words.
  int pictures = 0, pdfs = 0, pages = 0, capped = 0;
  for (const StickEntry& e : v_.stick) {
    pictures += !e.pdf;
    pdfs += e.pdf;
    pages += e.pdf ? std::max(e.pages, e.pages_in_file) : 0;
    capped = std::max(capped, e.pdf && e.pages_in_file > e.pages ? e.pages : 0);
  }
  const std::string page_words = msg_.word("summary_pages", pages);
  std::string pdf_part;
  if (pdfs == 1)
    pdf_part = msg_.word("summary_one_pdf", 1, {{"pages", page_words}});
  else if (pdfs > 1)
    pdf_part = msg_.word("summary_pdfs", pdfs, {{"pages", page_words}});
  if (capped > 0) pdf_part = msg_.word("summary_capped", capped, {{"pdfs", pdf_part}});
  const std::string picture_part = pictures > 0 ? msg_.word("summary_pictures", pictures) : std::string();
  const std::string what = pictures > 0 && pdfs > 0 ? msg_.word("summary_pictures_and_pdfs", 1,
                                                                {{"pictures", picture_part}, {"pdfs", pdf_part}})
                           : pictures > 0           ? picture_part
                                                    : pdf_part;
  return msg_.word("summary_all", 1,
                   {{"documents", msg_.word("summary_documents", static_cast<long>(v_.stick.size()))}, {"what", what}});
}

std::string spoken_name(const std::string& name, bool file_name) {
  std::string s = name;
  if (file_name) {
    const auto dot = s.find_last_of('.');
    if (dot != std::string::npos && dot > 0 && s.size() - dot <= 5) s.erase(dot);
    for (char& c : s)
      if (c == '_' || c == '-') c = ' ';
  }
  if (s.size() <= kSpokenNameBytes) return s;
  std::size_t cut = kSpokenNameBytes;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;  // a whole UTF-8 character
  const std::size_t space = s.rfind(' ', cut);
  if (space != std::string::npos && space >= kSpokenNameBytes / 2) cut = space;  // at a word
  s.erase(cut);
  while (!s.empty() && (s.back() == ' ' || s.back() == '.')) s.pop_back();
  return s;
}

std::string KioskFlow::document_name(const StickEntry& e) const {
  return e.title.empty() ? spoken_name(e.name, true) : spoken_name(e.title, false);
}

void KioskFlow::request(int document, int page, double now_s) {
  const bool awaited = v_.pending_picture >= 0 || v_.pending_doc >= 0;
  v_.pending_doc = v_.at_doc = document;
  v_.pending_page = v_.at_page = page;
  start_loading_clock(now_s, awaited);
  fx_.sticks.show_document(document, page);
}

void KioskFlow::start_loading_clock(double now_s, bool awaited) {
  // Keys pressed in a row while nothing has been said of the load awaited keep its clock, so "Loading." comes
  // loading_cue_s after the first of them, not after the last; once said, the next key gets its own.
  if (awaited && !v_.loading_said) return;
  v_.pending_since_s = now_s;
  v_.loading_said = false;
}

void KioskFlow::step_document(int delta, double now_s) {
  // From the last page asked for: the one awaited (a key pressed while loading moves on from there), or
  // the last one shown or found unreadable (so a visitor can step past a page that cannot be read).
  if (v_.stick.empty()) return;
  std::vector<int> pages;
  pages.reserve(v_.stick.size());
  for (const StickEntry& e : v_.stick) pages.push_back(e.pages);
  const StickPage to = step_stick_page(pages, {v_.at_doc, v_.at_page}, delta);
  request(to.document, to.page, now_s);
}

void KioskFlow::stick_inserted(const std::vector<StickEntry>& documents, double now_s, int unreadable) {
  guarded("a USB stick", [&] { stick_inserted_now(documents, now_s, unreadable); });
}

std::string KioskFlow::unreadable_line(int unreadable) const {
  if (unreadable <= 0) return {};
  return " " + counted(MessageId::files_unreadable, unreadable);
}

void KioskFlow::stick_inserted_now(const std::vector<StickEntry>& documents, double now_s, int unreadable) {
  activity(now_s);
  v_.stick = documents;
  v_.doc = v_.at_doc = v_.pending_doc = -1;
  if (v_.stick.empty()) {  // nothing to show: the visitor stays where they are (the tutorial's shape, a picture)
    v_.source = KioskSource::Library;
    std::string line = text(MessageId::stick_empty) + unreadable_line(unreadable);
    if (v_.state == KioskState::Attract) {  // a stick is someone at the kiosk: the tutorial starts, welcomed
      start_tutorial();
      line += " " + text(MessageId::welcome);
    }
    fx_.speech.say(line);
    return;
  }
  v_.state = KioskState::Picture;  // from Attract or the tutorial: the stick's first page comes
  v_.source = KioskSource::Stick;
  v_.announce_summary = stick_summary();
  v_.announce_unreadable = unreadable_line(unreadable);
  request(0, 1, now_s);
}

void KioskFlow::stick_refused(const std::string& reason, double now_s) {
  guarded("a USB stick", [&] {
    activity(now_s);
    std::string line = text(MessageId::stick_unreadable, {{"reason", reason}});
    if (v_.state == KioskState::Attract) {  // someone is at the kiosk: the tutorial starts, welcomed
      start_tutorial();
      if (!line.empty() && line.back() != '.' && line.back() != '!' && line.back() != '?') line += '.';
      line += " " + text(MessageId::welcome);
    }
    fx_.speech.say(line);
  });
}

void KioskFlow::stick_removed(double now_s) {
  guarded("taking out a USB stick", [&] { stick_removed_now(now_s); });
}

void KioskFlow::stick_removed_now(double now_s) {
  const bool browsing = v_.source == KioskSource::Stick;
  v_.stick.clear();
  v_.source = KioskSource::Library;
  v_.doc = v_.at_doc = v_.pending_doc = -1;
  v_.announce_summary.clear();
  if (!browsing || v_.state == KioskState::Attract) return;  // nothing of the stick was in use
  activity(now_s);
  if (v_.state == KioskState::Tutorial) {
    say(MessageId::stick_removed);
    return;
  }
  show(v_.picture, text(MessageId::stick_removed));
}

void KioskFlow::document_ready(const DocumentResult& r, double now_s) {
  guarded("a page of a USB stick", [&] { document_ready_now(r, now_s); });
}

void KioskFlow::document_ready_now(const DocumentResult& r, double now_s) {
  (void)now_s;
  if (!view().awaits_document(r.document, r.page)) return;  // superseded
  v_.pending_doc = -1;
  const StickEntry& e = v_.stick[static_cast<std::size_t>(r.document)];
  // A PDF's own title, when it has a usable one, names it: "Page 1 of 3 of Annual report 2025."
  const std::string name = document_name(e);
  std::string line;
  if (r.ok) {
    v_.felt = true;
    v_.doc = r.document;
    v_.page = r.page;
    v_.state = KioskState::Picture;
    v_.captured = false;
    line = e.pdf ? text(MessageId::document_page, {{"page", std::to_string(r.page)},
                                                   {"pages", std::to_string(std::max(e.pages, e.pages_in_file))},
                                                   {"name", name},
                                                   {"description", r.description}})
                 : text(MessageId::document_picture, {{"document", std::to_string(r.document + 1)},
                                                      {"documents", std::to_string(v_.stick.size())},
                                                      {"name", name},
                                                      {"description", r.description}});
  } else {
    const std::string what = e.pdf ? "Page " + std::to_string(r.page) + " of " + name : name;
    // "You still feel the picture before" only when there was one. Why is for the operator (the log and the
    // panel: StickDesk::problems), not words a visitor can act on.
    line = text(v_.felt ? MessageId::document_unreadable : MessageId::document_unreadable_alone, {{"name", what}});
  }
  if (!v_.announce_summary.empty()) {  // said now, so it names the keys of now
    line = text(MessageId::stick_inserted, {{"summary", v_.announce_summary}}) +
           std::exchange(v_.announce_unreadable, {}) + " " + line;
    v_.announce_summary.clear();
  }
  fx_.speech.say(line);
}

bool KioskFlow::awaits_library_picture(int index) const {
  return index == v_.pending_picture && v_.state == KioskState::Picture && !v_.captured &&
         v_.source == KioskSource::Library;
}

void KioskFlow::picture_ready(int index, int shapes, double now_s) {
  guarded("a picture of the library", [&] {
    (void)now_s;
    if (!awaits_library_picture(index)) return;  // superseded
    v_.pending_picture = -1;
    announce_picture(shapes, std::exchange(v_.pending_before, {}));
  });
}

void KioskFlow::picture_failed(int index, const std::string& reason, double now_s) {
  guarded("a picture of the library", [&] {
    (void)now_s;
    if (!awaits_library_picture(index)) return;  // superseded
    v_.pending_picture = -1;
    const std::string name =
        "Picture " + std::to_string(index + 1) + " of " + std::to_string(fx_.library.picture_count());
    spdlog::warn("kiosk: picture {} cannot be shown: {}", index + 1, reason);
    const std::string line = text(MessageId::document_unreadable, {{"name", name}});
    const std::string before = std::exchange(v_.pending_before, {});
    fx_.speech.say(before.empty() ? line : before + " " + line);
  });
}

}  // namespace hk::app
