#include "kiosk/operator_panel.hpp"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "haptics/level_policy.hpp"

#include "config/device_profile.hpp"
#include "config/load.hpp"
#include "pictures/picture_names.hpp"
#include "runtime/device_setup.hpp"

// N_ marks a word for the panel's catalogue (xgettext --keyword=N_) where it is looked up later with tr().
#define N_(text) text

namespace hk::app {
namespace {

const ImVec4 kRed{1.0f, 0.45f, 0.4f, 1.0f};
const ImVec4 kOrange{1.0f, 0.75f, 0.3f, 1.0f};
const ImVec4 kGrey{0.7f, 0.7f, 0.72f, 1.0f};
const ImVec4 kGreen{0.5f, 0.95f, 0.55f, 1.0f};

const char* apply_text(config::ApplyWhen a) {
  switch (a) {
    case config::ApplyWhen::live:
      return N_("at once");
    case config::ApplyWhen::scene:
      return N_("rebuilds the scene");
    case config::ApplyWhen::session:
      return N_("next visitor");
    case config::ApplyWhen::restart:
      return N_("after a restart");
  }
  return "";
}

constexpr config::FieldGroup kTabs[] = {
    config::FieldGroup::haptics, config::FieldGroup::levels, config::FieldGroup::scene,  config::FieldGroup::audio,
    config::FieldGroup::kiosk,   config::FieldGroup::keys,   config::FieldGroup::devices};

}  // namespace

std::string OperatorPanel::profile_limit_line(const config::ProfileLimit& limit) const {
  switch (limit.kind) {
    case config::ProfileLimit::Kind::force_everywhere:
      return format(tr("at most %.2f N (what the %s gives everywhere)"), limit.value, tr(limit.device.c_str()));
    case config::ProfileLimit::Kind::stable_stiffness:
      return format(tr("at most %.0f N/m (stable on the %s at %.0f Hz)"), limit.value, tr(limit.device.c_str()),
                    limit.servo_rate_hz);
    case config::ProfileLimit::Kind::within_max_force:
      return format(tr("at most max_force_n (%.2f N)"), limit.value);
  }
  return {};
}

void OperatorPanel::record(const std::string& name) {
  const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
  drawing_[name] = WidgetRect{a.x, a.y, b.x, b.y};
}

std::optional<WidgetRect> OperatorPanel::widget(const std::string& name) const {
  const auto it = widgets_.find(name);
  if (it == widgets_.end()) return std::nullopt;
  return it->second;
}

void OperatorPanel::draw(KioskRuntime& runtime, const KioskFlow& flow, int fw, int fh, double now_s,
                         std::int64_t now_unix_s) {
  drawing_.clear();
  s_.set_language(runtime.settings().operator_.language, audio::default_locale_dir());
  sample_plot(runtime);
  switch (s_.state()) {
    case PanelState::closed:
      std::fill(pin_.begin(), pin_.end(), '\0');
      pin_.clear();
      break;
    case PanelState::notice:
      draw_notice(fw, fh);
      break;
    case PanelState::pin_entry:
    case PanelState::checking:
      draw_pin_prompt(fw, fh, now_s, now_unix_s);
      break;
    case PanelState::open:
      draw_panel(runtime, flow, fw, fh, now_s, now_unix_s);
      break;
  }
  widgets_.swap(drawing_);
}

void OperatorPanel::draw_notice(int fw, int fh) {
  ImGui::SetNextWindowPos(ImVec2(0.5f * fw, 0.3f * fh), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(0.6f * fw, 0));
  ImGui::Begin((std::string(tr("Operator")) + "###operator_notice").c_str(), nullptr,
               ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoResize);
  ImGui::PushStyleColor(ImGuiCol_Text, kOrange);
  ImGui::TextWrapped("%s", s_.message().c_str());
  ImGui::PopStyleColor();
  ImGui::End();
}

void OperatorPanel::draw_pin_prompt(int fw, int fh, double now_s, std::int64_t now_unix_s) {
  ImGui::SetNextWindowPos(ImVec2(0.5f * fw, 0.3f * fh), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(0.6f * fw, 560.0f), 0));
  ImGui::Begin((std::string(tr("Operator PIN")) + "###operator_pin").c_str(), nullptr,
               ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoResize);
  if (ImGui::IsWindowAppearing()) focus_pin_ = true;
  ImGui::TextWrapped("%s", s_.message().c_str());
  const bool can_type = s_.state() == PanelState::pin_entry && s_.wait_s() <= 0;
  if (!can_type) ImGui::BeginDisabled();
  if (focus_pin_ && can_type) {
    ImGui::SetKeyboardFocusHere();
    focus_pin_ = false;
  }
  ImGui::SetNextItemWidth(-1);
  bool enter = ImGui::InputText(
      "##pin", &pin_,
      ImGuiInputTextFlags_Password | ImGuiInputTextFlags_CharsDecimal | ImGuiInputTextFlags_EnterReturnsTrue);
  record("pin");
  if (pin_.size() > static_cast<std::size_t>(12)) pin_.resize(12);
  enter = ImGui::Button((std::string(tr("OK")) + "###OK").c_str()) || enter;
  record("OK");
  if (!can_type) ImGui::EndDisabled();
  ImGui::SameLine();
  if (ImGui::Button((std::string(tr("Cancel")) + "###Cancel").c_str())) {
    std::fill(pin_.begin(), pin_.end(), '\0');
    pin_.clear();
    s_.close(now_unix_s);
  }
  record("Cancel");
  if (enter && can_type) {
    s_.submit_pin(std::move(pin_), now_s, now_unix_s);
    pin_.clear();
    focus_pin_ = true;  // ready for another try
  }
  ImGui::End();
}

void OperatorPanel::draw_panel(KioskRuntime& runtime, const KioskFlow& flow, int fw, int fh, double,
                               std::int64_t now_unix_s) {
  ImGui::SetNextWindowPos(ImVec2(0.04f * fw, 0.04f * fh));
  ImGui::SetNextWindowSize(ImVec2(0.92f * fw, 0.8f * fh));
  ImGui::SetNextWindowBgAlpha(0.96f);  // the picture must not show through the settings
  ImGui::Begin((std::string(tr("Operator panel")) + "###operator_panel").c_str(), nullptr,
               ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoResize);
  if (!s_.files().load_notice.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kOrange);
    ImGui::TextWrapped(tr("Settings file: %s"), s_.files().load_notice.c_str());
    ImGui::PopStyleColor();
  }
  ImGui::TextColored(kGrey, tr("%s   audit: %s"), s_.files().settings_path.c_str(), s_.files().audit_path.c_str());
  if (!s_.files().fleet_path.empty())
    ImGui::TextColored(kGrey, tr("Locked fields are set by the museum in %s."), s_.files().fleet_path.c_str());
  const float actions_h = ImGui::GetFrameHeightWithSpacing() * 2.2f;
  ImGui::BeginChild("tabs", ImVec2(0, -actions_h));
  if (ImGui::BeginTabBar("groups")) {
    if (ImGui::BeginTabItem((std::string(tr("Status")) + "###Status").c_str())) {
      draw_status(runtime, flow, now_unix_s);
      ImGui::EndTabItem();
    }
    record("tab:Status");
    for (config::FieldGroup g : kTabs) {
      const std::string name(config::group_name(g));
      const bool open = ImGui::BeginTabItem((std::string(tr(name.c_str())) + "###" + name).c_str());
      record("tab:" + name);
      if (open) {
        draw_fields(g, profile_type(runtime), now_unix_s);
        ImGui::EndTabItem();
      }
    }
    const bool names_open = ImGui::BeginTabItem((std::string(tr("Names")) + "###Names").c_str());
    record("tab:Names");
    if (names_open) {
      draw_names(runtime);
      ImGui::EndTabItem();
    }
    ImGui::EndTabBar();
  }
  ImGui::EndChild();
  draw_actions(now_unix_s);
  ImGui::End();
}

void OperatorPanel::draw_fields(config::FieldGroup group, const std::string& profile_type, std::int64_t now_unix_s) {
  if (!ImGui::BeginTable("fields", 4,
                         ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY | ImGuiTableFlags_SizingStretchProp))
    return;
  ImGui::TableSetupColumn(tr("setting"), ImGuiTableColumnFlags_WidthStretch, 1.3f);
  ImGui::TableSetupColumn(tr("value"), ImGuiTableColumnFlags_WidthStretch, 1.0f);
  ImGui::TableSetupColumn(tr("allowed"), ImGuiTableColumnFlags_WidthStretch, 1.0f);
  ImGui::TableSetupColumn(tr("takes effect"), ImGuiTableColumnFlags_WidthStretch, 0.6f);
  ImGui::TableHeadersRow();
  for (const config::FieldDescriptor& d : config::field_descriptors()) {
    if (d.group != group) continue;
    const std::string key = std::string(d.table) + "." + std::string(d.key);
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    // The setting in staff words, its key small and grey beside it for those who edit the file, then its help.
    const std::string help = s_.words()(d.help);  // in the staff's language
    ImGui::TextUnformatted(config::field_label(help, key).c_str());
    ImGui::SameLine();
    ImGui::SetWindowFontScale(0.8f);
    ImGui::TextColored(kGrey, "%s", key.c_str());
    ImGui::SetWindowFontScale(1.0f);
    ImGui::PushStyleColor(ImGuiCol_Text, kGrey);
    ImGui::TextWrapped("%s", help.c_str());
    ImGui::PopStyleColor();
    ImGui::TableNextColumn();
    ImGui::SetNextItemWidth(-1);
    ImGui::PushID(key.c_str());
    const bool locked = s_.managed(d);
    if (locked) ImGui::BeginDisabled();
    const bool enter = ImGui::InputText("##v", &s_.edit_text(d),
                                        ImGuiInputTextFlags_AutoSelectAll | ImGuiInputTextFlags_EnterReturnsTrue);
    if (locked) {
      ImGui::EndDisabled();
      ImGui::TextColored(kGrey, "%s", tr("locked: set by the museum"));
    }
    record(key);
    if (!locked && (enter || ImGui::IsItemDeactivatedAfterEdit())) s_.commit_field(d, now_unix_s);
    if (!s_.field_error(d).empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, kRed);
      ImGui::TextWrapped("%s", s_.field_error(d).c_str());
      ImGui::PopStyleColor();
    }
    ImGui::PopID();
    ImGui::TableNextColumn();
    if (d.kind == config::FieldKind::text && !d.choices.empty() && d.choices.size() > 6) {
      ImGui::TextWrapped("%s", tr("a key name (F1, A, UP, PAGE_UP, KP_5, ...)"));
    } else if (d.kind == config::FieldKind::text && d.check) {
      ImGui::TextWrapped("%s", tr("text"));
    } else {
      if (d.kind == config::FieldKind::text)
        ImGui::TextWrapped(tr("one of %s"), config::field_choices_text(d).c_str());
      else
        ImGui::TextWrapped("%s", config::field_allowed_text(d).c_str());
      if (const std::optional<config::ProfileLimit> limit =
              config::profile_limit(s_.working(), profile_type, d.table, d.key)) {
        ImGui::PushStyleColor(ImGuiCol_Text, kOrange);
        ImGui::TextWrapped("%s", profile_limit_line(*limit).c_str());
        ImGui::PopStyleColor();
      }
    }
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(tr(apply_text(d.apply)));
  }
  ImGui::EndTable();
}

void OperatorPanel::draw_actions(std::int64_t now_unix_s) {
  if (s_.dirty()) {
    ImGui::TextColored(kOrange, "%s", tr("Changed in the panel, not applied yet."));
  } else if (s_.unsaved()) {
    ImGui::TextColored(kOrange, "%s",
                       tr("Applied, not saved: the kiosk goes back to the file's settings when it restarts."));
  } else {
    ImGui::TextColored(kGreen, "%s", s_.status().empty() ? tr("In use and saved.") : s_.status().c_str());
  }
  if (!s_.status().empty() && (s_.dirty() || s_.unsaved())) {
    ImGui::SameLine();
    ImGui::TextColored(kGrey, "%s", s_.status().c_str());
  }
  if (ImGui::Button((std::string(tr("Apply")) + "###Apply").c_str())) s_.apply(now_unix_s);
  record("Apply");
  ImGui::SameLine();
  if (ImGui::Button((std::string(tr("Save")) + "###Save").c_str())) s_.save(now_unix_s);
  record("Save");
  ImGui::SameLine();
  if (ImGui::Button((std::string(tr("Reset to defaults")) + "###Reset to defaults").c_str()))
    ImGui::OpenPopup("###reset_popup");
  record("Reset to defaults");
  ImGui::SameLine();
  if (ImGui::Button((std::string(tr("Close")) + "###Close").c_str())) s_.close(now_unix_s);
  record("Close");
  if (ImGui::BeginPopupModal((std::string(tr("Reset to defaults?")) + "###reset_popup").c_str(), nullptr,
                             ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::TextUnformatted(
        tr("Every setting in the panel goes back to its default (the PIN stays).\nNothing changes in the kiosk until "
           "Apply."));
    if (ImGui::Button((std::string(tr("Reset")) + "###Reset").c_str())) {
      s_.reset_to_defaults(now_unix_s);
      ImGui::CloseCurrentPopup();
    }
    record("Reset");
    ImGui::SameLine();
    if (ImGui::Button((std::string(tr("Keep")) + "###Keep").c_str())) ImGui::CloseCurrentPopup();
    record("Keep");
    ImGui::EndPopup();
  }
}

void OperatorPanel::sample_plot(KioskRuntime& runtime) {
  const ServoDisplayState& d = runtime.core().display();
  const bool touching = d.state != ContactState::Free;
  force_n_[static_cast<std::size_t>(plot_at_)] = static_cast<float>(length(d.force_n));
  penetration_mm_[static_cast<std::size_t>(plot_at_)] =
      touching ? static_cast<float>(1000.0 * length(d.handle_m - d.proxy_m)) : 0.0f;
  plot_at_ = (plot_at_ + 1) % kPlotSamples;
}

void OperatorPanel::draw_stick_problems(KioskRuntime& runtime) {
  const std::vector<std::string>& problems = runtime.sticks().problems();
  if (problems.empty()) return;
  char title[160];
  std::snprintf(title, sizeof title,
                problems.size() >= StickDesk::kProblems
                    ? tr("The last stick: %zu files left out (the first ones; all in the log)")
                    : tr("The last stick: %zu file(s) left out (all in the log)"),
                problems.size());
  if (ImGui::TreeNode("stick_problems", "%s", title)) {
    for (const std::string& p : problems) ImGui::BulletText("%s", p.c_str());
    ImGui::TreePop();
  }
  record("stick_problems");
}

void OperatorPanel::draw_device(KioskRuntime& runtime, std::int64_t now_unix_s) {
  const ServoDisplayState& d = runtime.core().display();
  io::HaplyDevice* usb = runtime.devices().usb();
  if (!usb) {
    ImGui::Text(tr("Device: simulated pantograph%s%s"),
                runtime.devices().note().empty() ? "" : tr(" (no USB pantograph: "),
                runtime.devices().note().empty() ? "" : (runtime.devices().note() + ")").c_str());
    return;
  }
  const io::HaplyCounters c = usb->counters();
  ImGui::Text(tr("Device: %s, %s; replies missing %lld, refused %lld, reconnects %lld"), usb->name().c_str(),
              device_status_name(d.device_status), static_cast<long long>(c.replies_missing),
              static_cast<long long>(c.malformed), static_cast<long long>(c.reconnects));
  if (d.device_status != DeviceStatus::Ok) {
    ImGui::SameLine();
    ImGui::TextColored(kOrange, "%s", tr("(no force while it does not answer)"));
  }
  const double can_n = io::min_force_capability_n(usb->params());
  ImGui::Text(tr("%s profile: it gives at least %.2f N in every direction everywhere in its rectangle."),
              tr(std::string(config::device_profile(profile_type(runtime)).name).c_str()), can_n);
  if (!runtime.devices().home_note().empty()) ImGui::TextColored(kOrange, "%s", runtime.devices().home_note().c_str());
  if (ImGui::Button((std::string(tr("Calibrate: the handle rests at the park place")) + "###calibrate").c_str())) {
    double o1 = 0, o2 = 0;
    std::string why;
    if (runtime.devices().calibrate(&o1, &o2, &why)) {
      char text[32];
      for (const auto& [key, value] : {std::pair{"encoder1_offset_deg", o1}, std::pair{"encoder2_offset_deg", o2}}) {
        if (const config::FieldDescriptor* f = config::find_field("device", key)) {
          std::snprintf(text, sizeof text, "%.3f", value);
          s_.edit_text(*f) = text;
          s_.commit_field(*f, now_unix_s);
        }
      }
      char note[160];
      std::snprintf(note, sizeof note,
                    tr("Calibrated: encoder offsets %.3f and %.3f deg, in force now; Save keeps them."), o1, o2);
      calibrate_note_ = note;
    } else {
      calibrate_note_ = std::string(tr("Not calibrated:")) + " " + why + ".";
    }
  }
  record("button:Calibrate");
  if (!calibrate_note_.empty()) ImGui::TextWrapped("%s", calibrate_note_.c_str());
}

void OperatorPanel::draw_status(KioskRuntime& runtime, const KioskFlow& flow, std::int64_t now_unix_s) {
  const config::Settings& s = runtime.settings();
  const ServoDisplayState& d = runtime.core().display();
  ImGui::Text(tr("Visitor: %s, picture %d, %s%s"), state_name(flow.view().state), flow.view().picture + 1,
              level_label(d.level).c_str(), d.auto_level ? tr(" (from hand speed)") : tr(" (fixed)"));
  if (ServoThread* st = runtime.devices().servo()) {
    const ServoTimingStats t = st->stats();
    ImGui::Text(tr("Servo: %.0f Hz, %s; lateness p50 %.0f, p99 %.0f, max %.0f us; missed deadlines %lld"),
                s.haptics.servo_rate_hz, st->realtime() ? tr("real-time (SCHED_FIFO)") : tr("normal priority"),
                t.lateness_p50_us, t.lateness_p99_us, t.lateness_max_us, static_cast<long long>(t.missed_deadlines));
    if (t.missed_deadlines > 0) {
      ImGui::SameLine();
      ImGui::TextColored(kOrange, "%s", tr("(each one zeroed the force for a tick)"));
    }
  }
  draw_device(runtime, now_unix_s);
  ImGui::Text(tr("Walls: stiffness %.0f N/m, max force %.2f N"), s.haptics.stiffness_n_per_m, s.haptics.max_force_n);
  audio::AudioSystem& a = runtime.audio();
  ImGui::Text(tr("Sound: %s; speech %s; volume %d/10; cues dropped %llu"),
              a.sound_output() ? tr("playing") : tr("no sound device"),
              a.speech_available() ? tr("on") : tr("unavailable"), a.volume().step(),
              static_cast<unsigned long long>(a.cues_dropped()));
  ImGui::Text(tr("USB sticks: %s%s%s"),
              runtime.sticks().service().can_mount() ? tr("mounted read-only when inserted")
                                                     : tr("cannot mount (no CAP_SYS_ADMIN)"),
              flow.view().source == KioskSource::Stick ? tr("; a stick is being browsed") : "",
              runtime.sticks().busy() ? tr("; working") : "");
  record(runtime.sticks().busy() ? "sticks:working" : "sticks:idle");
  draw_stick_problems(runtime);
  ImGui::Checkbox(tr("Show the collision tree's boxes and the boundary section on screen"),
                  &runtime.switches().overlay());
  ImGui::Checkbox(tr("High contrast"), &runtime.switches().high_contrast());
  ImGui::Separator();
  const float w = ImGui::GetContentRegionAvail().x;
  ImGui::Text(tr("Force on the handle [N], last 5 s (now %.2f N)"), length(d.force_n));
  ImGui::PlotLines("##force", force_n_.data(), kPlotSamples, plot_at_, nullptr, 0.0f,
                   static_cast<float>(std::max(0.5, s.haptics.max_force_n)), ImVec2(w, 90));
  ImGui::Text(tr("Penetration into the wall [mm] (now %.2f mm)"),
              d.state != ContactState::Free ? 1000.0 * length(d.handle_m - d.proxy_m) : 0.0);
  ImGui::PlotLines("##penetration", penetration_mm_.data(), kPlotSamples, plot_at_, nullptr, 0.0f, FLT_MAX,
                   ImVec2(w, 90));
}

void OperatorPanel::draw_name_list() {
  const std::vector<NamesEntry>& entries = names_->entries();
  if (entries.empty()) ImGui::TextColored(kGrey, "%s", tr("No shape of this picture has a name yet."));
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const NamesEntry& e = entries[i];
    std::string label = (e.name.empty() ? std::string(tr("(no name)")) : e.name) + "  -  ";
    if (e.curves.empty()) label += tr("no shape");
    for (std::size_t k = 0; k < e.curves.size() && k < 8; ++k)
      label += (k == 0 ? std::string(e.curves.size() == 1 ? tr("shape") : tr("shapes")) + " " : std::string(", ")) +
               std::to_string(e.curves[k] + 1);
    if (e.curves.size() > 8) label += ", ...";
    if (!e.description.empty()) label += std::string("  ") + tr("(described)");
    ImGui::PushID(static_cast<int>(i));
    if (ImGui::Selectable(label.c_str(), names_->selected() == static_cast<int>(i)))
      names_->select_entry(static_cast<int>(i));
    ImGui::PopID();
    record("name:" + std::to_string(i));
  }
}

void OperatorPanel::draw_names(KioskRuntime& runtime) {
  Stage& stage = runtime.stage();
  const std::string folder = names_dir(runtime.settings());
  if (!names_ || names_->folder() != folder) {
    names_ = std::make_unique<NamesEditor>(folder);
    names_scene_ = 0;
  }
  if (names_scene_ != stage.scenes_published()) {  // another picture, or the same one built again
    names_scene_ = stage.scenes_published();
    const Shown& sh = stage.shown();
    const bool library = stage.source().picture >= 0 && stage.source().document < 0;
    const std::string path = library ? sh.image_path : std::string();
    names_->open({path, sh.picture, sh.file_width_px, sh.file_height_px, sh.px_to_m, sh.polylines, sh.descriptors,
                  sh.faces_m, sh.text_blocks, path.empty() || guesses_for(path, folder, sh.notes.guesses)});
  }
  if (!names_->is_open()) {
    ImGui::TextWrapped("%s", tr("Names are given to the library's pictures; what is on show is not one of them."));
    return;
  }
  ImGui::TextColored(kGrey, tr("%s   names: %s"), names_->picture_path().c_str(),
                     folder.empty() ? tr("no names folder ([kiosk] names_dir is off)") : names_->target_file().c_str());
  ImGui::BeginChild("names_list", ImVec2(0, ImGui::GetContentRegionAvail().y * 0.45f), true);
  draw_name_list();
  ImGui::EndChild();
  if (ImGui::Button((std::string(tr("Pick the shape at the handle")) + "###pick").c_str())) {
    const ServoDisplayState& d = runtime.core().display();
    names_->pick_at_hand(d.handle_m, d.scene_id == stage.shown_id() ? d.curve : -1);
  }
  record("Pick the shape at the handle");
  ImGui::SameLine();
  if (names_->picked_curve() >= 0)
    ImGui::Text(tr("Shape %d picked%s"), names_->picked_curve() + 1,
                names_->selected() >= 0 ? tr(" (named)") : tr(" (no name)"));
  else
    ImGui::TextColored(kGrey, "%s", tr("No shape picked: move the handle onto one, or click a name above."));
  ImGui::TextUnformatted(tr("Name"));
  ImGui::SetNextItemWidth(-1);
  ImGui::InputText("##names.name", &names_->name_text());
  record("names.name");
  ImGui::TextUnformatted(tr("Description (optional)"));
  ImGui::SetNextItemWidth(-1);
  ImGui::InputText("##names.description", &names_->description_text());
  record("names.description");
  bool saved = false;
  bool guesses = names_->guesses();
  if (ImGui::Checkbox(tr("The kiosk's own guesses (faces, text) name parts of this picture"), &guesses))
    saved = names_->set_guesses(guesses);
  record("names.guesses");
  if (ImGui::Button((std::string(tr("Save names")) + "###Save names").c_str())) saved = names_->save_typed();
  record("Save names");
  ImGui::SameLine();
  if (ImGui::Button((std::string(tr("Delete name")) + "###Delete name").c_str())) saved = names_->delete_and_save();
  record("Delete name");
  if (saved) stage.set_names(names_->regions(), names_->shape_region());  // Where and Describe say them at once
  const NamesSaved last = names_->last_save();
  if (!names_->status().empty())
    ImGui::TextColored(last == NamesSaved::failed ? kRed : (last == NamesSaved::saved ? kGreen : kGrey), "%s",
                       names_->status().c_str());
  else
    ImGui::TextColored(kGrey, "%s", names_->dirty() ? tr("Not saved yet.") : "");
  record("names:status");
  if (last != NamesSaved::none) record(last == NamesSaved::saved ? "names:saved" : "names:failed");
}

}  // namespace hk::app
