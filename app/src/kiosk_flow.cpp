#include "kiosk_flow.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace hk::app {

const char* state_name(KioskState s) {
  switch (s) {
    case KioskState::Attract: return "attract";
    case KioskState::Tutorial: return "tutorial";
    case KioskState::Picture: return "picture";
  }
  return "?";
}


using audio::MessageId;

KioskFlow::KioskFlow(KioskEffects& effects, const audio::MessageCatalog& messages, const KioskFlowParams& params)
    : fx_(effects), msg_(messages), p_(params) {
  p_.warning_s = std::min(p_.warning_s, 0.5 * p_.timeout_s);  // a warning must leave time to answer it
}

std::array<audio::KeyArg, audio::kKeyPlaceholders.size()> key_args(const config::KeysSettings& k) {
  // In the order of kKeyPlaceholders: help, next, previous, describe, finer, coarser, volume_up, volume_down, tutorial, guide,
  // capture.
  return {{{audio::kKeyPlaceholders[0], k.help},      {audio::kKeyPlaceholders[1], k.next},
           {audio::kKeyPlaceholders[2], k.previous},  {audio::kKeyPlaceholders[3], k.describe},
           {audio::kKeyPlaceholders[4], k.finer},     {audio::kKeyPlaceholders[5], k.coarser},
           {audio::kKeyPlaceholders[6], k.volume_up}, {audio::kKeyPlaceholders[7], k.volume_down},
           {audio::kKeyPlaceholders[8], k.tutorial},  {audio::kKeyPlaceholders[9], k.guide},
           {audio::kKeyPlaceholders[10], k.capture}}};
}

std::string KioskFlow::text(MessageId id, std::initializer_list<audio::MessageArg> args) const {
  return msg_.text(id, args, key_args(p_.keys));
}

void KioskFlow::say(MessageId id, std::initializer_list<audio::MessageArg> args) { fx_.say(text(id, args)); }

void KioskFlow::start_tutorial() {
  state_ = KioskState::Tutorial;
  shape_ = TutorialShape::Square;
  fx_.show_tutorial(shape_);
}

void KioskFlow::show(int index, const std::string& before) {
  const int n = fx_.picture_count();
  picture_ = ((index % n) + n) % n;  // wraps round both ways
  state_ = KioskState::Picture;
  const int shapes = fx_.show_picture(picture_);
  const std::string num = std::to_string(picture_ + 1), total = std::to_string(n);
  const std::string title = fx_.shown_notes().title;
  std::string line;
  if (!title.empty()) {
    // A person's words first: "Picture 2 of 5: a horse, seen from the side. It has 2 shapes."
    const MessageId id = shapes == 0 ? MessageId::picture_titled_empty : shapes == 1 ? MessageId::picture_titled_one : MessageId::picture_titled;
    line = text(id, {{"picture", num}, {"pictures", total}, {"title", title}, {"shapes", std::to_string(shapes)}});
  } else if (shapes == 0) {
    line = text(MessageId::picture_empty, {{"picture", num}, {"pictures", total}});
  } else if (shapes == 1) {
    line = text(MessageId::picture_loaded_one, {{"picture", num}, {"pictures", total}});
  } else {
    line = text(MessageId::picture_loaded, {{"picture", num}, {"pictures", total}, {"shapes", std::to_string(shapes)}});
  }
  fx_.say(before.empty() ? line : before + " " + line);
}

void KioskFlow::wake(double now_s) {
  last_activity_s_ = now_s;
  warned_ = false;
  start_tutorial();
  fx_.say(text(MessageId::welcome) + " " + text(MessageId::tutorial_start));
}

void KioskFlow::handle_moved(double now_s) {
  if (state_ == KioskState::Attract) {
    wake(now_s);
    return;
  }
  last_activity_s_ = now_s;
  warned_ = false;
}

void KioskFlow::key(KioskKey k, double now_s) {
  if (state_ == KioskState::Attract) {
    wake(now_s);
    return;
  }
  last_activity_s_ = now_s;
  warned_ = false;
  fx_.key_pressed();
  if (capturing_) {  // any key stops a capture, and does nothing else
    capturing_ = false;
    fx_.cancel_capture();
    say(MessageId::capture_cancelled);
    return;
  }
  switch (k) {
    case KioskKey::Capture:
      if (fx_.start_capture()) {
        capturing_ = true;
        say(MessageId::capture_start);
      } else {
        say(MessageId::capture_no_camera);
      }
      return;
    case KioskKey::Guide:
      fx_.guide();
      return;
    case KioskKey::Help:
      say_help();
      return;
    case KioskKey::Tutorial:
      start_tutorial();
      say(MessageId::tutorial_start);
      return;
    case KioskKey::VolumeUp:
      say(fx_.change_volume(+1) ? MessageId::volume_up : MessageId::volume_limit);
      return;
    case KioskKey::VolumeDown:
      say(fx_.change_volume(-1) ? MessageId::volume_down : MessageId::volume_limit);
      return;
    default:
      break;
  }
  if (source_ == KioskSource::Stick) {
    switch (k) {
      case KioskKey::Next:
        step_document(+1, now_s);
        return;
      case KioskKey::Previous:
        step_document(-1, now_s);
        return;
      default:
        break;
    }
  }
  if (state_ == KioskState::Tutorial) {
    switch (k) {
      case KioskKey::Next:
        if (shape_ == TutorialShape::Square) {
          shape_ = TutorialShape::Circle;
          fx_.show_tutorial(shape_);
          say(MessageId::tutorial_circle);
        } else if (shape_ == TutorialShape::Circle) {
          shape_ = TutorialShape::Triangle;
          fx_.show_tutorial(shape_);
          say(MessageId::tutorial_triangle);
        } else {
          show(0, text(MessageId::tutorial_done));
        }
        return;
      case KioskKey::Previous:
        if (shape_ != TutorialShape::Square) shape_ = static_cast<TutorialShape>(static_cast<int>(shape_) - 1);
        fx_.show_tutorial(shape_);
        say(shape_ == TutorialShape::Square ? MessageId::tutorial_start : MessageId::tutorial_circle);
        return;
      case KioskKey::Describe:
        fx_.say(fx_.describe());
        return;
      default:
        say_help();  // any other key still gets an answer
        return;
    }
  }
  switch (k) {  // Picture
    case KioskKey::Next:
      show(picture_ + 1);
      return;
    case KioskKey::Previous:
      show(picture_ - 1);
      return;
    case KioskKey::Describe:
      fx_.say(text(MessageId::describe, {{"description", fx_.describe()}}));
      return;
    case KioskKey::Finer:
      say(fx_.change_level(-1) ? MessageId::level_finer : MessageId::level_finest);
      return;
    case KioskKey::Coarser:
      say(fx_.change_level(+1) ? MessageId::level_coarser : MessageId::level_coarsest);
      return;
    default:
      say_help();
      return;
  }
}

void KioskFlow::say_help() {
  fx_.say(p_.camera ? text(MessageId::help) + " " + text(MessageId::help_camera) : text(MessageId::help));
}

void KioskFlow::capture_advice(MessageId advice, double now_s) {
  if (!capturing_) return;
  last_activity_s_ = now_s;
  warned_ = false;
  say(advice);
}

void KioskFlow::capture_done(int shapes, double now_s) {
  if (!capturing_) return;
  capturing_ = false;
  last_activity_s_ = now_s;
  warned_ = false;
  state_ = KioskState::Picture;
  if (shapes == 0) {
    say(MessageId::captured_empty);
  } else if (shapes == 1) {
    say(MessageId::captured_one);
  } else {
    say(MessageId::captured, {{"shapes", std::to_string(shapes)}});
  }
}

void KioskFlow::capture_failed(bool timeout, double now_s) {
  if (!capturing_) return;
  capturing_ = false;
  last_activity_s_ = now_s;
  say(timeout ? MessageId::capture_timeout : MessageId::capture_failed);
}

void KioskFlow::tick(double now_s) {
  if (state_ == KioskState::Attract) return;
  if (pending_doc_ >= 0 && !loading_said_ && now_s - pending_since_s_ > p_.loading_cue_s) {
    loading_said_ = true;
    say(MessageId::loading);
  }
  const double idle = now_s - last_activity_s_;
  if (idle >= p_.timeout_s) {
    if (capturing_) fx_.cancel_capture();
    capturing_ = false;
    fx_.new_session();  // first: it stops speech, and the goodbye must be heard
    if (source_ == KioskSource::Stick || !stick_.empty()) fx_.forget_stick();
    source_ = KioskSource::Library;
    stick_.clear();
    doc_ = at_doc_ = pending_doc_ = -1;
    say(MessageId::goodbye);
    state_ = KioskState::Attract;
    warned_ = false;
    return;
  }
  if (!warned_ && idle >= p_.timeout_s - p_.warning_s) {
    warned_ = true;
    say(MessageId::timeout_warning, {{"seconds", std::to_string(static_cast<int>(std::lround(p_.timeout_s - idle)))}});
  }
}

std::string KioskFlow::stick_summary() const {
  // English phrase for {summary}; the sentence around it comes from the catalogue.
  int pictures = 0, pdfs = 0, pages = 0;
  for (const StickEntry& e : stick_) {
    pictures += !e.pdf;
    pdfs += e.pdf;
    pages += e.pdf ? e.pages : 0;
  }
  auto count = [](int n, const char* one, const char* many) { return n == 1 ? std::string(one) : std::to_string(n) + " " + many; };
  const int n = static_cast<int>(stick_.size());
  std::string s = count(n, "one document", "documents") + ": ";
  std::string pdf_part;
  if (pdfs == 1) {
    pdf_part = "a PDF of " + count(pages, "one page", "pages");
  } else if (pdfs > 1) {
    pdf_part = std::to_string(pdfs) + " PDFs of " + count(pages, "one page", "pages") + " in all";
  }
  if (pictures > 0 && pdfs > 0) return s + count(pictures, "a picture", "pictures") + " and " + pdf_part;
  if (pictures > 0) return s + count(pictures, "a picture", "pictures");
  return s + pdf_part;
}

void KioskFlow::request(int document, int page, double now_s) {
  pending_doc_ = at_doc_ = document;
  pending_page_ = at_page_ = page;
  pending_since_s_ = now_s;
  loading_said_ = false;
  fx_.show_document(document, page);
}

void KioskFlow::step_document(int delta, double now_s) {
  // From the last page asked for: the one awaited (a key pressed while loading moves on from there), or
  // the last one shown or found unreadable (so a visitor can step past a page that cannot be read).
  int d = at_doc_;
  int p = at_page_;
  const int n = static_cast<int>(stick_.size());
  if (d < 0) {
    d = delta > 0 ? 0 : n - 1;
    p = delta > 0 ? 1 : stick_[static_cast<std::size_t>(d)].pages;
  } else if (delta > 0) {
    if (++p > stick_[static_cast<std::size_t>(d)].pages) {
      d = (d + 1) % n;
      p = 1;
    }
  } else if (--p < 1) {
    d = (d - 1 + n) % n;
    p = stick_[static_cast<std::size_t>(d)].pages;
  }
  request(d, p, now_s);
}

void KioskFlow::stick_inserted(const std::vector<StickEntry>& documents, double now_s) {
  last_activity_s_ = now_s;
  warned_ = false;
  if (state_ == KioskState::Attract) state_ = KioskState::Picture;  // a stick is someone at the kiosk
  if (state_ == KioskState::Tutorial) state_ = KioskState::Picture;
  stick_ = documents;
  doc_ = at_doc_ = pending_doc_ = -1;
  if (stick_.empty()) {
    source_ = KioskSource::Library;
    say(MessageId::stick_empty);
    return;
  }
  source_ = KioskSource::Stick;
  announce_summary_ = stick_summary();
  request(0, 1, now_s);
}

void KioskFlow::stick_refused(const std::string& reason, double now_s) {
  last_activity_s_ = now_s;
  warned_ = false;
  if (state_ == KioskState::Attract) state_ = KioskState::Picture;
  say(MessageId::stick_unreadable, {{"reason", reason}});
}

void KioskFlow::stick_removed(double now_s) {
  const bool browsing = source_ == KioskSource::Stick;
  stick_.clear();
  source_ = KioskSource::Library;
  doc_ = at_doc_ = pending_doc_ = -1;
  announce_summary_.clear();
  if (!browsing || state_ == KioskState::Attract) return;  // nothing of the stick was in use
  last_activity_s_ = now_s;
  warned_ = false;
  if (state_ == KioskState::Tutorial) {
    say(MessageId::stick_removed);
    return;
  }
  show(picture_, text(MessageId::stick_removed));
}

void KioskFlow::document_ready(const DocumentResult& r, double now_s) {
  (void)now_s;
  if (source_ != KioskSource::Stick || r.document != pending_doc_ || r.page != pending_page_) return;  // superseded
  pending_doc_ = -1;
  const StickEntry& e = stick_[static_cast<std::size_t>(r.document)];
  // A PDF's own title, when it has a usable one, names it: "Page 1 of 3 of Annual report 2025."
  const std::string& name = e.title.empty() ? e.name : e.title;
  std::string line;
  if (r.ok) {
    doc_ = r.document;
    page_ = r.page;
    state_ = KioskState::Picture;
    line = e.pdf ? text(MessageId::document_page, {{"page", std::to_string(r.page)}, {"pages", std::to_string(e.pages)},
                                                          {"name", name}, {"description", r.description}})
                 : text(MessageId::document_picture, {{"document", std::to_string(r.document + 1)},
                                                             {"documents", std::to_string(stick_.size())},
                                                             {"name", name}, {"description", r.description}});
  } else {
    const std::string what = e.pdf ? "Page " + std::to_string(r.page) + " of " + name : name;
    line = text(MessageId::document_unreadable, {{"name", what}, {"reason", r.reason}});
  }
  if (!announce_summary_.empty()) {  // said now, so it names the keys of now
    line = text(MessageId::stick_inserted, {{"summary", announce_summary_}}) + " " + line;
    announce_summary_.clear();
  }
  fx_.say(line);
}

}  // namespace hk::app
