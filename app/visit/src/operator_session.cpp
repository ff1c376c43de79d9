#include "visit/operator_session.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <limits>

#include "config/operator_pin.hpp"
#include "config/store.hpp"
#include "visit/pin_verifier.hpp"

namespace hk::app {
namespace {

constexpr double kNoticeS = 8.0;  // a notice stays this long [s]

std::string wait_text(double wait_s) {
  if (std::isinf(wait_s))
    return "The PIN is locked after too many failed attempts: set it again with 'haptic-kiosk pin set'.";
  return "Try again in " + std::to_string(static_cast<long long>(std::ceil(wait_s))) + " s.";
}

}  // namespace

OperatorSession::OperatorSession(std::string settings_path, const config::Settings& in_use, std::string load_notice,
                                 ApplyFn apply)
    : files_{std::move(settings_path), {}, std::move(load_notice)},
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
        "The kiosk runs on its built-in settings: start it with --config FILE, and set a PIN with 'haptic-kiosk pin "
        "set --config FILE'.";
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
    message_ = "No operator PIN is set. Set one with: haptic-kiosk pin set --config " + files_.settings_path;
    spdlog::warn("operator panel: {}", message_);
    return;
  }
  state_ = PanelState::pin_entry;
  wait_s_ = st.verdict == config::PinVerdict::locked ? st.wait_s : 0.0;
  notice_until_s_ = now_s + wait_s_;  // when the wait ends (frame clock)
  message_ = wait_s_ > 0 ? wait_text(wait_s_) : "Enter the operator's PIN, then Enter.";
}

void OperatorSession::submit_pin(std::string pin, double now_s, std::int64_t now_unix_s) {
  last_input_s_ = now_s;
  if (state_ != PanelState::pin_entry || wait_s_ > 0 || !verifier_) {
    std::fill(pin.begin(), pin.end(), '\0');
    return;
  }
  if (verifier_->submit(std::move(pin), now_unix_s)) {
    state_ = PanelState::checking;
    message_ = "Checking...";
  }
}

void OperatorSession::tick(double now_s, std::int64_t now_unix_s) {
  if (state_ == PanelState::notice && now_s >= notice_until_s_) state_ = PanelState::closed;
  if (state_ == PanelState::pin_entry && wait_s_ > 0) {
    wait_s_ = std::isinf(wait_s_) ? wait_s_ : std::max(0.0, notice_until_s_ - now_s);
    message_ = wait_s_ > 0 ? wait_text(wait_s_) : "Enter the operator's PIN, then Enter.";
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
            message_ = "Wrong PIN (" + std::to_string(o->attempt.failures) + " failed attempts).";
            if (o->attempt.wait_s > 0) message_ += " " + wait_text(o->attempt.wait_s);
            spdlog::warn("operator panel: a wrong PIN ({} failed attempts)", o->attempt.failures);
            audit_event(now_unix_s, "PIN refused, " + std::to_string(o->attempt.failures) + " failed attempts");
            break;
          case config::PinVerdict::locked:
            message_ = wait_text(o->attempt.wait_s);
            break;
          case config::PinVerdict::no_pin:
            state_ = PanelState::notice;
            notice_until_s_ = now_s + kNoticeS;
            message_ = "No operator PIN is set. Set one with: haptic-kiosk pin set --config " + files_.settings_path;
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

std::string OperatorSession::commit_field(const config::FieldDescriptor& d, std::int64_t) {
  const std::size_t i = index_of(d);
  std::string why = config::set_field_from_text(working_, d, edit_texts_[i]);
  field_errors_[i] = why;
  if (why.empty()) edit_texts_[i] = config::field_text(working_, d);
  return why;
}

std::string OperatorSession::apply(std::int64_t now_unix_s) {
  const std::vector<config::SettingChange> changes = config::diff_settings(in_use_, working_);
  if (changes.empty()) return status_ = "Nothing to apply.";
  status_ = apply_fn_ ? apply_fn_(working_) : std::string("Applied.");
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
      to_save.operator_.pin_hash = config::load_settings(files_.settings_path).operator_.pin_hash;
    } catch (const config::ConfigError&) {
      // The file on disk is unreadable: ours is the one to write.
    }
    config::save_settings_atomic(to_save, files_.settings_path);
  } catch (const std::exception& e) {
    status_ = std::string("Not saved: ") + e.what();
    spdlog::error("operator panel: {}", e.what());
    return status_;
  }
  in_use_.operator_.pin_hash = to_save.operator_.pin_hash;
  working_.operator_.pin_hash = to_save.operator_.pin_hash;
  saved_ = in_use_;
  status_ = "Saved to " + files_.settings_path + " (the previous file kept as .bak).";
  spdlog::info("operator panel: saved {}", files_.settings_path);
  audit_event(now_unix_s, "saved " + files_.settings_path);
  return status_;
}

void OperatorSession::reset_to_defaults(std::int64_t now_unix_s) {
  config::Settings d;
  d.operator_ = working_.operator_;
  working_ = d;
  const auto fields = config::field_descriptors();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    edit_texts_[i] = config::field_text(working_, fields[i]);
    field_errors_[i].clear();
  }
  status_ = "Defaults restored in the panel: Apply to use them, Save to keep them.";
  audit_event(now_unix_s, "reset to defaults (not applied yet)");
}

}  // namespace hk::app
