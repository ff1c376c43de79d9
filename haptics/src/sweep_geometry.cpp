// Sweep geometry of the collision query, the public entries: Liang–Barsky clipping of a segment against a box,
// and the first crossing of a sweep with a segment (seed paper §3). Their bodies are inline in
// collision_query_internal.hpp, where the query's inner loops inline them.
#include "collision_query_internal.hpp"

namespace hk {

bool clip_segment_box(const ErrorBox& box, Vec2 a, Vec2 b, double margin_m, double* t_enter, double* t_exit) noexcept {
  return clip_segment_box_inline(box, a, b, margin_m, t_enter, t_exit);
}

bool intersect_sweep_segment(Vec2 a, Vec2 b, Vec2 p, Vec2 q, double* t) noexcept {
  return intersect_sweep_segment_inline(a, b, p, q, t);
}

}  // namespace hk
