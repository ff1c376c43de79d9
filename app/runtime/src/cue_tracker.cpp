#include "runtime/cue_tracker.hpp"

#include <cmath>

namespace hk::app {

using audio::CueEvent;
using audio::CueKind;

void CueTracker::reset() noexcept {
  have_prev_ = false;
  prev_curve_ = -1;
  prev_level_ = -1;
  at_edge_ = false;
  slide_path_m_ = 0;
  slide_ticks_ = 0;
  in_text_block_ = -1;
}

namespace {

bool in_box(const Aabb& b, Vec2 p, double margin_m) {
  return p.x >= b.lo.x - margin_m && p.x <= b.hi.x + margin_m && p.y >= b.lo.y - margin_m && p.y <= b.hi.y + margin_m;
}

}  // namespace

int CueTracker::update(std::int64_t tick, const ServoOutput& out, Vec2 handle_m, int level_in_use,
                       CueEvent* cues) noexcept {
  int n = 0;
  auto emit = [&](CueKind kind, int curve, double speed, int level) {
    if (n >= kMaxCuesPerTick) return;
    CueEvent& e = cues[n++];
    e.tick = tick;
    e.kind = kind;
    e.curve = curve;
    e.speed_m_per_s = static_cast<float>(speed);
    e.level = static_cast<std::int16_t>(level);
  };
  const ContactOutput& c = out.contact;
  const bool in_contact = c.state != ContactState::Free;
  const int curve = in_contact ? c.constraint[0].curve : -1;

  if (prev_level_ >= 0 && level_in_use != prev_level_) {
    emit(level_in_use < prev_level_ ? CueKind::LevelFiner : CueKind::LevelCoarser, curve, 0.0, level_in_use);
  }
  prev_level_ = level_in_use;

  // A push-through ends the contact with its own sound, in place of the soft tock of letting go.
  if (c.events & kEventPopThrough) {
    emit(CueKind::PopThrough, prev_curve_, 0.0, level_in_use);
  } else if (c.events & kEventContactEnd) {
    emit(CueKind::ContactEnd, prev_curve_, 0.0, level_in_use);
  }
  if (c.events & kEventContactBegin) {
    emit(CueKind::ContactBegin, curve, length(out.handle_velocity_m_per_s), level_in_use);
  } else if (in_contact && prev_curve_ >= 0 && curve != prev_curve_) {
    emit(CueKind::ContactBegin, curve, length(out.handle_velocity_m_per_s), level_in_use);  // onto another shape
  }
  const bool sharp = c.corner_turn_rad >= p_.corner_min_turn_rad;
  if ((c.events & kEventVertexBegin) && sharp) emit(CueKind::VertexContact, curve, 0.0, level_in_use);
  if ((c.events & kEventConvexCorner) && sharp && !(c.events & kEventVertexBegin))
    emit(CueKind::ConvexCorner, curve, 0.0, level_in_use);

  if (c.state == ContactState::Edge && have_prev_) {
    slide_path_m_ += length(c.proxy_m - prev_proxy_);
    if (++slide_ticks_ >= p_.slide_every_ticks) {
      emit(CueKind::Slide, curve, slide_path_m_ / (slide_ticks_ * p_.period_s), level_in_use);
      slide_path_m_ = 0;
      slide_ticks_ = 0;
    }
  } else {
    slide_path_m_ = 0;
    slide_ticks_ = 0;
  }

  const double dx = p_.workspace_half_extent_m.x - std::fabs(handle_m.x);
  const double dy = p_.workspace_half_extent_m.y - std::fabs(handle_m.y);
  const double inside = std::fmin(dx, dy);  // distance to the nearest border [m]
  if (!at_edge_ && inside <= p_.edge_margin_m) {
    at_edge_ = true;
    emit(CueKind::WorkspaceEdge, -1, 0.0, level_in_use);
  } else if (at_edge_ && inside > 2 * p_.edge_margin_m) {
    at_edge_ = false;
  }

  if (in_text_block_ >= 0 && !in_box(text_blocks_[in_text_block_], c.proxy_m, p_.text_block_margin_m))
    in_text_block_ = -1;
  for (int b = 0; b < text_block_count_; ++b) {
    if (b != in_text_block_ && in_box(text_blocks_[b], c.proxy_m, 0.0)) {
      in_text_block_ = b;
      emit(CueKind::TextBlock, b, 0.0, level_in_use);
      break;
    }
  }

  prev_proxy_ = c.proxy_m;
  prev_curve_ = curve;
  have_prev_ = true;
  return n;
}

}  // namespace hk::app
