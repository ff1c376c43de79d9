#include "kiosk/hud.hpp"

#include <imgui.h>

#include <algorithm>

#include "haptics/level_policy.hpp"

namespace hk::app {
void draw_captions(KioskRuntime& app, const KioskFlow& flow, int fw, int fh) {
  const std::string caption = flow.view().state == KioskState::Attract
                                  ? app.audio().messages().raw(audio::MessageId::attract)
                                  : app.voice().last_said();
  ImGui::SetNextWindowPos(ImVec2(0.05f * fw, 0.86f * fh));
  ImGui::SetNextWindowSize(ImVec2(0.9f * fw, 0.13f * fh));
  ImGui::SetNextWindowBgAlpha(0.75f);
  ImGui::Begin("caption", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoSavedSettings);
  ImGui::SetWindowFontScale(std::max(1.5f, fh / 400.0f));
  ImGui::TextWrapped("%s", caption.c_str());
  ImGui::End();
}

void draw_overlay_status(KioskRuntime& app, const KioskFlow& flow) {
  const ServoDisplayState& d = app.core().display();
  ImGui::SetNextWindowPos(ImVec2(10, 10));
  ImGui::Begin("overlay", nullptr,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoInputs |
                   ImGuiWindowFlags_NoSavedSettings);
  ImGui::Text("state %s   picture %d   %s%s", state_name(flow.view().state), flow.view().picture + 1,
              level_label(d.level).c_str(), d.auto_level ? " (auto)" : "");
  ImGui::Text("contact %d   curve %d   force %.2f N", static_cast<int>(d.state), d.curve, length(d.force_n));
  if (ServoThread* st = app.devices().servo()) {
    const ServoTimingStats t = st->stats();
    ImGui::Text("servo %.0f Hz %s   late p50 %.0f p99 %.0f max %.0f us", app.settings().haptics.servo_rate_hz,
                st->realtime() ? "FIFO" : "normal", t.lateness_p50_us, t.lateness_p99_us, t.lateness_max_us);
    ImGui::Text("tick work p50 %.0f p99 %.0f us   missed %lld", t.compute_p50_us, t.compute_p99_us,
                static_cast<long long>(t.missed_deadlines));
  }
  ImGui::Text("volume %d/10   sound %s   cues dropped %llu", app.audio().volume().step(),
              app.audio().sound_output() ? "on" : "no device",
              static_cast<unsigned long long>(app.audio().cues_dropped()));
  ImGui::End();
}

}  // namespace hk::app
