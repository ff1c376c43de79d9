// The operator's panel's logic (operator_session.hpp). Every line it shows is a tr("…") / trn("…") template in the
// panel's catalogue (app/kiosk/po); the audit log and the journal stay English.
#include "visit/operator_session.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "config/operator_pin.hpp"
#include "config/store.hpp"
#include "visit/fleet_settings.hpp"
#include "visit/pin_verifier.hpp"

namespace hk::app {
namespace {

constexpr double kNoticeS = 8.0;  // a notice stays this long [s]

}  // namespace

OperatorSession::OperatorSession(std::string settings_path, const config::Settings& in_use, std::string load_notice,
                                 ApplyFn apply)
    : files_{std::move(settings_path), {}, std::move(load_notice), {}},
      apply_fn_(std::move(apply)),
      in_use_(in_use),
      saved_(in_use),
      working_(in_use) {
  if (!files_.settings_path.empty()) {
    files_.audit_path = config::audit_log_path(in_use, files_.settings_path);
    verifier_ = std::make_unique<PinVerifier>(files_.settings_path);
  }
  const std::size_t n = config::field_descriptors().size();
  edit_texts_.resize(n);
  field_errors_.resize(n);
}

OperatorSession::~OperatorSession() = default;

void OperatorSession::set_language(const std::string& language, const std::filesystem::path& locale_dir) {
  if (language != words_.asked()) words_ = PanelText::load(language, locale_dir);
}

std::string OperatorSession::prompt_line(double wait_s) const {
  if (std::isinf(wait_s))
    return tr("The PIN is locked after too many failed attempts: set it again with 'haptic-kiosk pin set'.");
  if (wait_s <= 0) return tr("Enter the operator's PIN, then Enter.");
  const long long s = static_cast<long long>(std::ceil(wait_s));
  return format(trn("Try again in %lld second.", "Try again in %lld seconds.", s), s);
}

std::string OperatorSession::refusal_line(const config::FieldDescriptor& d, const std::string& typed,
                                          const std::string& loader_line) const {
  const std::string allowed = config::field_allowed_text(d);
  const std::string t = typed.size() > 80 ? typed.substr(0, 80) + "..." : typed;
  switch (config::field_refusal(d, typed)) {
    case config::FieldRefusal::not_a_number:
      return format(tr("\"%s\" is not a number; allowed: %s"), t.c_str(), allowed.c_str());
    case config::FieldRefusal::not_an_integer:
      return format(tr("%s is not a whole number; allowed: %s"), t.c_str(), allowed.c_str());
    case config::FieldRefusal::out_of_range:
      return format(tr("%s is out of range %s"), t.c_str(), allowed.c_str());
    case config::FieldRefusal::not_a_choice:
      return format(tr("\"%s\" is not one of the choices: %s"), t.c_str(), config::field_choices_text(d).c_str());
    case config::FieldRefusal::none:   // a rule across fields
    case config::FieldRefusal::other:  // the field's own check, which says why in English
      break;
  }
  return loader_line;
}

std::string OperatorSession::applied_line(const ApplyReport& r) const {
  std::string s = tr("Applied");
  const auto part = [&s](const std::string& p) { s += "; " + p; };
  if (r.gains) part(tr("forces changing now"));
  if (r.scene_rebuilt) part(tr("scene rebuilt"));
  if (r.keys) part(tr("keys changed"));
  if (r.timing) part(tr("session timing changed"));
  const long next = static_cast<long>(r.next_session.size()), restart = static_cast<long>(r.restart.size());
  if (next > 0) part(format(trn("%ld setting for the next visitor", "%ld settings for the next visitor", next), next));
  if (restart > 0) part(format(trn("%ld setting after a restart", "%ld settings after a restart", restart), restart));
  for (const std::string& why : r.refused) part(format(tr("refused: %s"), why.c_str()));
  return s + ".";
}

std::size_t OperatorSession::index_of(const config::FieldDescriptor& d) const {
  return static_cast<std::size_t>(&d - config::field_descriptors().data());
}

void OperatorSession::audit_event(std::int64_t now_unix_s, const std::string& event) {
  if (files_.audit_path.empty()) return;
  try {
    config::append_audit_event(files_.audit_path, now_unix_s, "panel", event);
  } catch (const std::exception& e) {
    spdlog::error("operator panel: {}", e.what());
  }
}

void OperatorSession::chord(double now_s, std::int64_t now_unix_s) {
  if (state_ != PanelState::closed && state_ != PanelState::notice) return;
  last_input_s_ = now_s;
  if (files_.settings_path.empty()) {
    state_ = PanelState::notice;
    notice_until_s_ = now_s + kNoticeS;
    message_ =
        tr("The kiosk runs on its built-in settings: start it with --config FILE, and set a PIN with 'haptic-kiosk "
           "pin set --config FILE'.");
    spdlog::warn("operator panel: {}", message_);
    return;
  }
  config::PinAttempt st;
  try {
    st = config::pin_status(files_.settings_path, now_unix_s);
  } catch (const std::exception& e) {
    state_ = PanelState::notice;
    notice_until_s_ = now_s + kNoticeS;
    message_ = e.what();
    spdlog::error("operator panel: {}", message_);
    return;
  }
  if (st.verdict == config::PinVerdict::no_pin) {
    state_ = PanelState::notice;
    notice_until_s_ = now_s + kNoticeS;
    message_ = format(tr("No operator PIN is set. Set one with: haptic-kiosk pin set --config %s"),
                      files_.settings_path.c_str());
    spdlog::warn("operator panel: {}", message_);
    return;
  }
  state_ = PanelState::pin_entry;
  wait_s_ = st.verdict == config::PinVerdict::locked ? st.wait_s : 0.0;
  notice_until_s_ = now_s + wait_s_;  // when the wait ends (frame clock)
  message_ = prompt_line(wait_s_);
}

void OperatorSession::submit_pin(std::string pin, double now_s, std::int64_t now_unix_s) {
  last_input_s_ = now_s;
  if (state_ != PanelState::pin_entry || wait_s_ > 0 || !verifier_) {
    std::fill(pin.begin(), pin.end(), '\0');
    return;
  }
  if (verifier_->submit(std::move(pin), now_unix_s)) {
    state_ = PanelState::checking;
    message_ = tr("Checking...");
  }
}

void OperatorSession::tick(double now_s, std::int64_t now_unix_s) {
  if (state_ == PanelState::notice && now_s >= notice_until_s_) state_ = PanelState::closed;
  if (state_ == PanelState::pin_entry && wait_s_ > 0) {
    wait_s_ = std::isinf(wait_s_) ? wait_s_ : std::max(0.0, notice_until_s_ - now_s);
    message_ = prompt_line(wait_s_);
  }
  if (state_ == PanelState::checking && verifier_) {
    if (std::optional<PinOutcome> o = verifier_->poll()) {
      state_ = PanelState::pin_entry;
      last_input_s_ = now_s;
      if (!o->error.empty()) {
        message_ = o->error;
        spdlog::error("operator panel: {}", o->error);
      } else {
        switch (o->attempt.verdict) {
          case config::PinVerdict::right:
            open_panel(now_s, now_unix_s);
            return;
          case config::PinVerdict::wrong:
            message_ =
                format(trn("Wrong PIN (%d failed attempt).", "Wrong PIN (%d failed attempts).", o->attempt.failures),
                       o->attempt.failures);
            if (o->attempt.wait_s > 0) message_ += " " + prompt_line(o->attempt.wait_s);
            spdlog::warn("operator panel: a wrong PIN ({} failed attempts)", o->attempt.failures);
            audit_event(now_unix_s, "PIN refused, " + std::to_string(o->attempt.failures) + " failed attempts");
            break;
          case config::PinVerdict::locked:
            message_ = prompt_line(o->attempt.wait_s);
            break;
          case config::PinVerdict::no_pin:
            state_ = PanelState::notice;
            notice_until_s_ = now_s + kNoticeS;
            message_ = format(tr("No operator PIN is set. Set one with: haptic-kiosk pin set --config %s"),
                              files_.settings_path.c_str());
            return;
        }
        wait_s_ = o->attempt.wait_s;
        notice_until_s_ = now_s + (std::isinf(wait_s_) ? 0.0 : wait_s_);
      }
    }
  }
  const double idle_s = in_use_.operator_.idle_close_s;
  if ((state_ == PanelState::pin_entry || state_ == PanelState::open) && now_s - last_input_s_ > idle_s) {
    spdlog::info("operator panel: closed after {:.0f} s without input", idle_s);
    close(now_unix_s);
  }
}

void OperatorSession::open_panel(double now_s, std::int64_t now_unix_s) {
  state_ = PanelState::open;
  last_input_s_ = now_s;
  working_ = in_use_;
  const auto fields = config::field_descriptors();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    edit_texts_[i] = config::field_text(working_, fields[i]);
    field_errors_[i].clear();
  }
  status_.clear();
  message_.clear();
  spdlog::info("operator panel: opened");
  audit_event(now_unix_s, "panel opened");
}

void OperatorSession::close(std::int64_t now_unix_s) {
  if (state_ == PanelState::open) {
    audit_event(now_unix_s, unsaved() ? "panel closed (changes applied, not saved)" : "panel closed");
  }
  state_ = PanelState::closed;
  working_ = in_use_;
  message_.clear();
}

std::string& OperatorSession::edit_text(const config::FieldDescriptor& d) { return edit_texts_[index_of(d)]; }

const std::string& OperatorSession::field_error(const config::FieldDescriptor& d) const {
  return field_errors_[index_of(d)];
}

void OperatorSession::set_fleet(std::string path, std::vector<std::string> managed) {
  files_.fleet_path = std::move(path);
  managed_ = std::move(managed);
}

bool OperatorSession::managed(const config::FieldDescriptor& d) const {
  const std::string key = std::string(d.table) + "." + std::string(d.key);
  return std::find(managed_.begin(), managed_.end(), key) != managed_.end();
}

std::string OperatorSession::commit_field(const config::FieldDescriptor& d, std::int64_t) {
  const std::size_t i = index_of(d);
  if (managed(d)) {
    edit_texts_[i] = config::field_text(working_, d);
    return field_errors_[i] =
               format(tr("Set by the museum in %s: change it there, for every kiosk."), files_.fleet_path.c_str());
  }
  const std::string loader_line = config::set_field_from_text(working_, d, edit_texts_[i]);
  if (loader_line.empty()) {
    field_errors_[i].clear();
    edit_texts_[i] = config::field_text(working_, d);
    return {};
  }
  return field_errors_[i] = refusal_line(d, edit_texts_[i], loader_line);
}

std::string OperatorSession::apply(std::int64_t now_unix_s) {
  const std::vector<config::SettingChange> changes = config::diff_settings(in_use_, working_);
  if (changes.empty()) return status_ = tr("Nothing to apply.");
  status_ = applied_line(apply_fn_ ? apply_fn_(working_) : ApplyReport{});
  in_use_ = working_;
  if (!files_.audit_path.empty()) {
    try {
      config::append_audit(files_.audit_path, now_unix_s, "panel", changes);
    } catch (const std::exception& e) {
      spdlog::error("operator panel: {}", e.what());
      status_ += " (" + std::string(e.what()) + ")";
    }
  }
  for (const auto& c : changes) spdlog::info("operator panel: {} {} -> {}", c.key, c.old_value, c.new_value);
  return status_;
}

std::string OperatorSession::save(std::int64_t now_unix_s) {
  if (dirty()) apply(now_unix_s);
  config::Settings to_save = in_use_;
  try {
    // A `pin set` made while the panel was open must not be undone: the hash on disk wins.
    try {
      const config::Settings on_disk = config::load_settings(files_.settings_path);
      to_save.operator_.pin_hash = on_disk.operator_.pin_hash;
      to_save = keep_own(to_save, on_disk, managed_);  // the museum's values stay in fleet.toml
    } catch (const config::ConfigError&) {
      // The file on disk is unreadable: ours is the one to write.
    }
    config::save_settings_atomic(to_save, files_.settings_path);
  } catch (const std::exception& e) {
    status_ = format(tr("Not saved: %s"), e.what());
    spdlog::error("operator panel: {}", e.what());
    return status_;
  }
  in_use_.operator_.pin_hash = to_save.operator_.pin_hash;
  working_.operator_.pin_hash = to_save.operator_.pin_hash;
  saved_ = in_use_;
  status_ = format(tr("Saved to %s (the previous file kept as .bak)."), files_.settings_path.c_str());
  spdlog::info("operator panel: saved {}", files_.settings_path);
  audit_event(now_unix_s, "saved " + files_.settings_path);
  return status_;
}

void OperatorSession::reset_to_defaults(std::int64_t now_unix_s) {
  config::Settings d;
  d.operator_ = working_.operator_;
  working_ = keep_own(d, working_, managed_);
  const auto fields = config::field_descriptors();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    edit_texts_[i] = config::field_text(working_, fields[i]);
    field_errors_[i].clear();
  }
  status_ = tr("Defaults restored in the panel: Apply to use them, Save to keep them.");
  audit_event(now_unix_s, "reset to defaults (not applied yet)");
}

}  // namespace hk::app
