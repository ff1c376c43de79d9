#include "visit/kiosk_flow.hpp"

#include "runtime/event_log.hpp"
#include "runtime/metrics.hpp"

#include "audio/speech.hpp"
#include "pictures/stick_pages.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <exception>
#include <utility>

namespace hk::app {

const char* state_name(KioskState s) {
  switch (s) {
    case KioskState::Attract:
      return "attract";
    case KioskState::Tutorial:
      return "tutorial";
    case KioskState::Picture:
      return "picture";
  }
  return "?";
}

using audio::MessageId;

namespace {

/// The message naming what key `k` does (learning mode), in KioskKey order.
constexpr std::array<MessageId, static_cast<std::size_t>(KioskKey::Other)> kKeyDoes{MessageId::key_help,
                                                                                    MessageId::key_next,
                                                                                    MessageId::key_previous,
                                                                                    MessageId::key_describe,
                                                                                    MessageId::key_finer,
                                                                                    MessageId::key_coarser,
                                                                                    MessageId::key_volume_up,
                                                                                    MessageId::key_volume_down,
                                                                                    MessageId::key_tutorial,
                                                                                    MessageId::key_guide,
                                                                                    MessageId::key_capture,
                                                                                    MessageId::key_repeat,
                                                                                    MessageId::key_pause,
                                                                                    MessageId::key_where,
                                                                                    MessageId::key_finish,
                                                                                    MessageId::key_next_sentence,
                                                                                    MessageId::key_previous_sentence,
                                                                                    MessageId::key_next_paragraph,
                                                                                    MessageId::key_previous_paragraph,
                                                                                    MessageId::key_language,
                                                                                    MessageId::key_copy};

}  // namespace

KioskFlow::KioskFlow(KioskEffects effects, const audio::MessageCatalog& messages, const KioskFlowParams& params)
    : fx_(effects), msg_(messages), p_(params) {
  p_.warning_s = std::min(p_.warning_s, 0.5 * p_.timeout_s);  // a warning must leave time to answer it
  v_.next_invitation_s = p_.attract_every_s;
}

std::array<audio::KeyArg, audio::kKeyPlaceholders.size()> key_args(const config::KeysSettings& k) {
  static_assert(audio::kKeyPlaceholders.size() == config::kKeyActionCount, "one placeholder per [keys] action");
  const auto actions = config::key_actions(k);
  std::array<audio::KeyArg, audio::kKeyPlaceholders.size()> args;
  for (std::size_t i = 0; i < args.size(); ++i) args[i] = {audio::kKeyPlaceholders[i], actions[i].second};
  return args;
}

KioskFlowParams flow_params_from(const config::Settings& s, bool camera) {
  KioskFlowParams fp;
  fp.timeout_s = s.kiosk.timeout_s;
  fp.warning_s = s.kiosk.warning_s;
  fp.attract_every_s = s.kiosk.attract_every_s;
  fp.keys = s.keys;
  fp.camera = camera;
  fp.copies = s.copy.to != "off";
  fp.copy_per_visit = s.copy.per_visit;
  return fp;
}

FlowView KioskFlow::view() const {
  FlowView f;
  f.state = v_.state;
  f.tutorial_shape = v_.shape;
  f.picture = v_.picture;
  f.source = v_.source;
  f.document = v_.doc;
  f.page = v_.page;
  f.stick_documents = v_.stick;
  f.loading = v_.pending_doc >= 0;
  f.picture_pending = v_.pending_picture >= 0;
  f.capturing = v_.capturing;
  f.warned = v_.warned;
  f.in_help = v_.help_group >= 0;
  f.reading = reading();
  f.reading_place = v_.reading.place();
  f.failures = failures_;
  f.pending_document = v_.pending_doc;
  f.pending_page = v_.pending_page;
  return f;
}

std::string KioskFlow::text(MessageId id, std::initializer_list<audio::MessageArg> args) const {
  return msg_.text(id, args, key_args(p_.keys));
}

std::string KioskFlow::counted(MessageId id, long count, std::initializer_list<audio::MessageArg> args) const {
  return msg_.text(id, count, args, key_args(p_.keys));
}

void KioskFlow::say(MessageId id, std::initializer_list<audio::MessageArg> args) { fx_.speech.say(text(id, args)); }

void KioskFlow::say_brief(MessageId id, std::initializer_list<audio::MessageArg> args) {
  fx_.speech.say_brief(text(id, args));
}

void KioskFlow::set_timing(double timeout_s, double warning_s, double attract_every_s) {
  p_.timeout_s = timeout_s;
  p_.warning_s = std::min(warning_s, 0.5 * timeout_s);
  p_.attract_every_s = attract_every_s;
}

// ---- the guard ---------------------------------------------------------------------------------------

void KioskFlow::guarded(const char* what, const std::function<void()>& action) {
  const Visit before = v_;
  try {
    action();
  } catch (const std::exception& e) {
    // The visit as it was; what failed goes to the log, the visitor hears one short line.
    v_ = before;
    ++failures_;
    kiosk_metrics().error(KioskError::visitor_action);
    spdlog::error("kiosk: {} failed: {}", what, e.what());
    try {
      say_brief(MessageId::sorry);
    } catch (const std::exception& again) {
      spdlog::error("kiosk: the sorry line failed too: {}", again.what());
    }
  }
}

// ---- keys --------------------------------------------------------------------------------------------

void KioskFlow::key(KioskKey k, double now_s, std::string_view key_name) {
  guarded("a key press", [&] { act_on_key(k, now_s, key_name); });
}

void KioskFlow::act_on_key(KioskKey k, double now_s, std::string_view key_name) {
  if (v_.state == KioskState::Attract) {
    // The Language key answers the invitation just heard: the visit starts in its language.
    wake(now_s, k == KioskKey::Language);
    return;
  }
  activity(now_s);
  if (learning_ && k != KioskKey::Help) {
    learn_key(k, key_name);
    return;
  }
  if (k == KioskKey::VolumeUp || k == KioskKey::VolumeDown) {
    volume_key(k == KioskKey::VolumeUp ? +1 : -1);
    return;
  }
  if (k != KioskKey::Finish) v_.finish_asked_s = -1;  // any other key: Finish asks again
  if (k != KioskKey::Copy) v_.copy_asked_s = -1;      // and Copy
  fx_.tour.key_pressed();
  if (v_.capturing) {  // any key stops a capture, and does nothing else
    v_.capturing = false;
    fx_.camera.cancel_capture();
    say(MessageId::capture_cancelled);
    return;
  }
  const int help_layer = v_.help_layer;
  v_.help_layer = 0;
  if (k == KioskKey::Help) {
    v_.help_layer = help_layer;
    help_key();
    return;
  }
  if (v_.help_group >= 0) {  // stepping through help: Next and Previous move within it, any other key leaves it
    if (k == KioskKey::Previous || (k == KioskKey::Next && v_.help_group + 1 < help_group_count())) {
      v_.help_group = std::max(0, v_.help_group + (k == KioskKey::Next ? 1 : -1));
      say_help_group();
      return;
    }
    v_.help_group = -1;
  }
  if (session_key(k, now_s)) return;
  if (v_.source == KioskSource::Stick && (k == KioskKey::Next || k == KioskKey::Previous)) {
    step_document(k == KioskKey::Next ? +1 : -1, now_s);
    return;
  }
  if (k == KioskKey::Other) {
    stray_key(key_name);
    return;
  }
  if (v_.state == KioskState::Tutorial) {
    tutorial_key(k);
  } else {
    picture_key(k);
  }
}

bool KioskFlow::session_key(KioskKey k, double now_s) {
  switch (k) {
    case KioskKey::Capture:
      if (fx_.camera.start_capture()) {
        v_.capturing = true;
        say(MessageId::capture_start);
      } else {
        say(MessageId::capture_no_camera);
      }
      return true;
    case KioskKey::Guide:
      fx_.tour.guide();
      return true;
    case KioskKey::Tutorial:
      start_tutorial();
      say(MessageId::tutorial_start);
      return true;
    case KioskKey::Repeat:
      repeat_key();
      return true;
    case KioskKey::NextSentence:
    case KioskKey::PreviousSentence:
    case KioskKey::NextParagraph:
    case KioskKey::PreviousParagraph:
      reading_key(k);
      return true;
    case KioskKey::Pause:
      pause_key();
      return true;
    case KioskKey::Where: {
      const std::string here = fx_.stage.where();
      if (!here.empty())
        fx_.speech.say(here);
      else
        fx_.speech.say(place());
      return true;
    }
    case KioskKey::Finish:
      finish_key(now_s);
      return true;
    case KioskKey::Language:
      language_key();
      return true;
    case KioskKey::Copy:
      copy_key(now_s);
      return true;
    default:
      return false;
  }
}

void KioskFlow::volume_key(int delta) {
  // Never cuts speech: while something is being said, it getting louder or quieter is the answer.
  const bool changed = fx_.session.change_volume(delta);
  if (fx_.speech.speaking()) return;
  say_brief(!changed ? MessageId::volume_limit : delta > 0 ? MessageId::volume_up : MessageId::volume_down);
}

void KioskFlow::finish_key(double now_s) {
  if (v_.finish_asked_s >= 0 && now_s - v_.finish_asked_s <= kFinishConfirm_s) {
    end_session(now_s);
    return;
  }
  v_.finish_asked_s = now_s;
  say_brief(MessageId::finish_ask);
}

void KioskFlow::level_key(int delta) {
  const bool was_auto = fx_.stage.auto_level();
  const bool changed = fx_.stage.change_level(delta);
  std::string line = text(changed ? (delta < 0 ? MessageId::level_finer : MessageId::level_coarser)
                                  : (delta < 0 ? MessageId::level_finest : MessageId::level_coarsest));
  if (changed && was_auto) line += " " + text(MessageId::level_manual);
  fx_.speech.say_brief(line);
}

void KioskFlow::pause_key() {
  if (fx_.speech.resume_speech()) return;  // pressed again: goes on from where it stopped
  if (fx_.speech.pause_speech()) return;   // silence is the answer
  say_brief(MessageId::nothing_to_pause);
}

void KioskFlow::help_key() {
  // One sentence for where the visitor is and the two most useful keys; the same key again for every key, a
  // few at a time.
  if (v_.help_layer == 1) {
    v_.help_layer = 0;
    v_.help_group = 0;
    say_help_group();
    return;
  }
  v_.help_layer = 1;
  v_.help_group = -1;
  say(MessageId::help_brief, {{"place", place()}});
}

std::vector<std::string> KioskFlow::help_groups() const {
  // The catalogue's help (and the camera's sentence) cut into sentences, kHelpSentencesPerGroup to a group.
  std::string all = msg_.raw(MessageId::help);
  if (p_.camera) all += " " + msg_.raw(MessageId::help_camera);
  if (p_.copies) all += " " + msg_.raw(MessageId::help_copy);
  std::vector<std::string> sentences;
  std::size_t from = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const bool end = (all[i] == '.' || all[i] == '!' || all[i] == '?') && (i + 1 == all.size() || all[i + 1] == ' ');
    if (!end) continue;
    sentences.push_back(all.substr(from, i + 1 - from));
    from = i + 1;
    while (from < all.size() && all[from] == ' ') ++from;
  }
  if (from < all.size()) sentences.push_back(all.substr(from));
  std::vector<std::string> groups;
  for (std::size_t i = 0; i < sentences.size(); ++i) {
    if (i % kHelpSentencesPerGroup == 0) groups.emplace_back();
    groups.back() += (groups.back().empty() ? "" : " ") + sentences[i];
  }
  return groups;
}

int KioskFlow::help_group_count() const { return static_cast<int>(help_groups().size()); }

void KioskFlow::say_help_group() {
  const std::vector<std::string> groups = help_groups();
  if (groups.empty()) return;
  const int g = std::clamp(v_.help_group, 0, static_cast<int>(groups.size()) - 1);
  std::string line = msg_.expand(groups[static_cast<std::size_t>(g)], {}, key_args(p_.keys));
  // Where each key of the group lies, in the order the group names them.
  const auto actions = config::key_actions(p_.keys);
  for (std::size_t i = 0; i < audio::kKeyPlaceholders.size(); ++i) {
    const std::string tag = "{" + std::string(audio::kKeyPlaceholders[i]) + "}";
    if (groups[static_cast<std::size_t>(g)].find(tag) != std::string::npos)
      line += key_place_sentence(actions[i].second);
  }
  line += " " + text(g + 1 < static_cast<int>(groups.size()) ? MessageId::help_next : MessageId::help_last);
  fx_.speech.say(line);
}

std::string KioskFlow::key_place_sentence(std::string_view key_name) const {
  const std::string place = msg_.key_place(key_name);
  if (place.empty()) return {};
  return " " + text(MessageId::key_place, {{"key", spoken_key(key_name)}, {"place", place}});
}

void KioskFlow::learn_key(KioskKey k, std::string_view key_name) {
  if (k == KioskKey::Other) {
    stray_key(key_name);
    return;
  }
  const std::string name(config::key_actions(p_.keys)[static_cast<std::size_t>(k)].second);
  fx_.speech.say_brief(text(kKeyDoes[static_cast<std::size_t>(k)]) + key_place_sentence(name));
}

void KioskFlow::stray_key(std::string_view key_name) {
  say_brief(MessageId::key_other, {{"key", spoken_key(key_name)}});
}

std::string KioskFlow::spoken_key(std::string_view key_name) const {
  if (key_name.empty() || !msg_.key_names().contains(key_name)) return text(MessageId::this_key);
  std::string name = msg_.key_name(key_name);
  if (!name.empty()) name[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(name[0])));
  return name;
}

void KioskFlow::tutorial_key(KioskKey k) {
  switch (k) {
    case KioskKey::Next:
      if (v_.shape == TutorialShape::Square) {
        v_.shape = TutorialShape::Circle;
        fx_.stage.show_tutorial(v_.shape);
        say(MessageId::tutorial_circle);
      } else if (v_.shape == TutorialShape::Circle) {
        v_.shape = TutorialShape::Triangle;
        fx_.stage.show_tutorial(v_.shape);
        say(MessageId::tutorial_triangle);
      } else {
        show(0, text(MessageId::tutorial_done));
      }
      return;
    case KioskKey::Previous:
      if (v_.shape != TutorialShape::Square) v_.shape = static_cast<TutorialShape>(static_cast<int>(v_.shape) - 1);
      fx_.stage.show_tutorial(v_.shape);
      say(v_.shape == TutorialShape::Square ? MessageId::tutorial_start : MessageId::tutorial_circle);
      return;
    case KioskKey::Describe:
      fx_.speech.say(fx_.stage.describe());
      return;
    case KioskKey::Finer:
    case KioskKey::Coarser:  // no levels to change on a practice shape: said why
      say_brief(MessageId::tutorial_no_levels);
      return;
    default:
      say_brief(kKeyDoes[static_cast<std::size_t>(k)]);
      return;
  }
}

void KioskFlow::picture_key(KioskKey k) {
  switch (k) {
    case KioskKey::Next:
      show(v_.picture + 1);
      return;
    case KioskKey::Previous:
      show(v_.picture - 1);
      return;
    case KioskKey::Describe:
      describe_key();
      return;
    case KioskKey::Finer:
      level_key(-1);
      return;
    case KioskKey::Coarser:
      level_key(+1);
      return;
    default:
      return;
  }
}

std::string KioskFlow::place() const {
  if (v_.state == KioskState::Tutorial) return text(MessageId::place_tutorial);
  if (v_.source == KioskSource::Stick && v_.doc >= 0) {
    const StickEntry& e = v_.stick[static_cast<std::size_t>(v_.doc)];
    return text(MessageId::place_document,
                {{"page", std::to_string(v_.page)}, {"pages", std::to_string(std::max(e.pages, e.pages_in_file))}});
  }
  if (v_.captured) return text(MessageId::place_capture);
  return text(MessageId::place_picture,
              {{"picture", std::to_string(v_.picture + 1)}, {"pictures", std::to_string(fx_.library.picture_count())}});
}

// ---- the session -------------------------------------------------------------------------------------

void KioskFlow::activity(double now_s) {
  v_.last_activity_s = now_s;
  v_.warned = false;
  v_.rewarned = false;
}

void KioskFlow::start_tutorial() {
  v_.felt = true;
  v_.state = KioskState::Tutorial;
  v_.shape = TutorialShape::Square;
  v_.captured = false;
  fx_.stage.show_tutorial(v_.shape);
}

void KioskFlow::show(int index, const std::string& before) {
  const int n = fx_.library.picture_count();
  const int from = v_.state == KioskState::Picture && !v_.captured ? v_.picture : -1;
  v_.picture = fx_.library.moving_to(((index % n) + n) % n, from);  // wraps round both ways; a new listing taken
  v_.state = KioskState::Picture;
  v_.felt = true;
  v_.captured = false;
  const int shapes = fx_.library.show_picture(v_.picture);
  if (shapes == KioskEffects::kPicturePending) {  // built off the window thread: announced when it is felt
    const bool awaited = v_.pending_picture >= 0 || v_.pending_doc >= 0;
    v_.pending_picture = v_.picture;
    v_.pending_before = before;
    start_loading_clock(v_.last_activity_s, awaited);
    return;
  }
  v_.pending_picture = -1;
  announce_picture(shapes, before);
}

void KioskFlow::announce_picture(int shapes, const std::string& before) {
  const int n = fx_.library.picture_count();
  const std::string num = std::to_string(v_.picture + 1), total = std::to_string(n);
  const std::string title = fx_.stage.shown_notes().title;
  std::string line;
  if (!title.empty()) {
    // A person's words first: "Picture 2 of 5: a horse, seen from the side. It has 2 shapes."
    line = shapes == 0
               ? text(MessageId::picture_titled_empty, {{"picture", num}, {"pictures", total}, {"title", title}})
               : counted(MessageId::picture_titled, shapes, {{"picture", num}, {"pictures", total}, {"title", title}});
  } else if (shapes == 0) {
    line = text(MessageId::picture_empty, {{"picture", num}, {"pictures", total}});
  } else {
    line = counted(MessageId::picture_loaded, shapes, {{"picture", num}, {"pictures", total}});
  }
  fx_.speech.say(before.empty() ? line : before + " " + line);
}

void KioskFlow::wake(double now_s, bool keep_language) {
  if (!keep_language) fx_.speech.set_language(fx_.speech.default_language());
  activity(now_s);
  v_.help_layer = 0;
  v_.started_s = now_s;
  log_event(KioskEvent::visit_started, spdlog::level::info, "visit: started");
  start_tutorial();
  say(MessageId::welcome);
}

void KioskFlow::end_session(double now_s) {
  if (v_.capturing) fx_.camera.cancel_capture();
  fx_.session.new_session();  // first: it stops speech, and the goodbye must be heard
  if (v_.source == KioskSource::Stick || !v_.stick.empty()) fx_.sticks.forget_stick();
  if (v_.started_s >= 0)
    log_event(KioskEvent::visit_finished, spdlog::level::info,
              fmt::format("visit: finished after {:.0f} s, {} cop{} made", now_s - v_.started_s, v_.copies_made,
                          v_.copies_made == 1 ? "y" : "ies"));
  v_ = Visit{};
  v_.next_invitation_s = now_s + p_.attract_every_s;
  say_brief(MessageId::goodbye);  // in the visitor's language; the next visit starts in the default
  fx_.speech.set_language(fx_.speech.default_language());
}

void KioskFlow::handle_moved(double now_s) {
  guarded("handle motion", [&] {
    if (v_.state == KioskState::Attract) {
      wake(now_s, false);
      return;
    }
    activity(now_s);
  });
}

void KioskFlow::touching(double now_s) {
  guarded("touching a shape", [&] {
    if (v_.state == KioskState::Attract) return;
    activity(now_s);
    // On the tutorial's square, once the welcome has been heard: the wall the hand feels can be pushed through.
    if (v_.state == KioskState::Tutorial && v_.shape == TutorialShape::Square && !v_.push_taught &&
        !fx_.speech.speaking()) {
      v_.push_taught = true;
      say_brief(MessageId::tutorial_push);
    }
  });
}

void KioskFlow::tick(double now_s) {
  guarded("the session's clock", [&] {
    if (v_.state == KioskState::Attract) {
      if (p_.attract_every_s > 0 && now_s >= v_.next_invitation_s) {
        v_.next_invitation_s = now_s + p_.attract_every_s;
        if (!fx_.speech.quiet_hours()) invite();
      }
      return;
    }
    // Speech being heard is the visitor listening (a long text being read is never cut by the time-out);
    // the warning's own speech is not.
    if (!v_.warned && fx_.speech.speaking()) activity(now_s);
    follow_reading();
    read_more();
    if ((v_.pending_doc >= 0 || v_.pending_picture >= 0) && !v_.loading_said &&
        now_s - v_.pending_since_s > p_.loading_cue_s) {
      v_.loading_said = true;
      say_brief(MessageId::loading);
    }
    const double idle = now_s - v_.last_activity_s;
    if (idle >= p_.timeout_s) {
      end_session(now_s);
      return;
    }
    if (!v_.warned && idle >= p_.timeout_s - p_.warning_s) {
      v_.warned = true;
      v_.warned_at_s = now_s;
      warn(idle);
    } else if (v_.warned && !v_.rewarned && now_s - v_.warned_at_s >= kRewarn_s && p_.timeout_s - idle >= 3.0) {
      v_.rewarned = true;  // once more, while there is still time to answer it
      warn(idle);
    }
  });
}

void KioskFlow::warn(double idle_s) {
  const MessageId id = v_.source == KioskSource::Stick ? MessageId::timeout_warning_stick : MessageId::timeout_warning;
  say_brief(id, {{"seconds", std::to_string(static_cast<int>(std::lround(p_.timeout_s - idle_s)))}});
}

}  // namespace hk::app
