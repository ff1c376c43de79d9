// Embree 3 peer: user-geometry segments, our segment test in the callbacks (see embree_peer.hpp).
#include "embree_peer.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "haptics/collision_query.hpp"

namespace hk::bench {
namespace {

using Segments = std::vector<std::pair<Vec2, Vec2>>;

// The intersect context carries the sweep in double: Embree's ray is float, our test is not.
struct SweepContext {
  RTCIntersectContext rtc;  // first member: Embree hands this pointer back to the callback
  Vec2 a, b;
  const Segments* segs;
};

// The point query's user data: the point in double and the best distance so far.
struct PointContext {
  Vec2 p;
  const Segments* segs;
  double best;
};

// Float bounds around a double: one ulp past the nearest float.
float below(double v) { return std::nextafter(static_cast<float>(v), -std::numeric_limits<float>::infinity()); }
float above(double v) { return std::nextafter(static_cast<float>(v), std::numeric_limits<float>::infinity()); }

// Embree traverses with the ray in float, rounded from our double sweep: the boxes grow by this much
// more than that rounding (a few float ulps of workspace coordinates, ~1e-8 m), so no segment is culled
// that the double sweep meets. 0.1 µm is nothing to the BVH's pruning.
constexpr double kBoundsPad_m = 1e-7;

void segment_bounds(const RTCBoundsFunctionArguments* args) {
  const auto& s = (*static_cast<const Segments*>(args->geometryUserPtr))[args->primID];
  RTCBounds* o = args->bounds_o;
  o->lower_x = below(std::min(s.first.x, s.second.x) - kBoundsPad_m);
  o->lower_y = below(std::min(s.first.y, s.second.y) - kBoundsPad_m);
  o->lower_z = -1e-6f;
  o->upper_x = above(std::max(s.first.x, s.second.x) + kBoundsPad_m);
  o->upper_y = above(std::max(s.first.y, s.second.y) + kBoundsPad_m);
  o->upper_z = 1e-6f;
}

void segment_intersect(const RTCIntersectFunctionNArguments* args) {
  if (!args->valid[0]) return;
  const auto* ctx = reinterpret_cast<const SweepContext*>(args->context);
  const auto& s = (*ctx->segs)[args->primID];
  double t = 0.0;
  if (!intersect_sweep_segment(ctx->a, ctx->b, s.first, s.second, &t)) return;
  RTCRayHit* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);  // N == 1: rtcIntersect1 only
  // The exact best t so far lives in the 8 bytes of Ng_x and Ng_y; tfar holds it rounded up to a float,
  // so Embree skips only boxes that begin past it.
  double best = std::numeric_limits<double>::infinity();
  if (rh->hit.geomID != RTC_INVALID_GEOMETRY_ID) std::memcpy(&best, &rh->hit.Ng_x, sizeof best);
  if (t >= best) return;
  std::memcpy(&rh->hit.Ng_x, &t, sizeof t);
  rh->ray.tfar = above(t);
  rh->hit.geomID = args->geomID;
  rh->hit.primID = args->primID;
}

bool segment_point_query(RTCPointQueryFunctionArguments* args) {
  auto* ctx = static_cast<PointContext*>(args->userPtr);
  const auto& s = (*ctx->segs)[args->primID];
  const double d = distance_to_segment(ctx->p, s.first, s.second);
  if (d >= ctx->best) return false;
  ctx->best = d;
  args->query->radius = above(d);
  return true;
}

[[noreturn]] void fail(RTCDevice device, const char* what) {
  const RTCError e = device ? rtcGetDeviceError(device) : RTC_ERROR_UNKNOWN;
  throw std::runtime_error(std::string("Embree: ") + what + " failed (error " + std::to_string(static_cast<int>(e)) +
                           ")");
}

bool count_bytes(void* user, ssize_t bytes, bool /*post*/) {
  static_cast<std::atomic<long long>*>(user)->fetch_add(bytes, std::memory_order_relaxed);
  return true;
}

}  // namespace

EmbreeIndex::EmbreeIndex(const std::vector<std::pair<Vec2, Vec2>>& segs) : segs_(segs) {
  RTCDevice device = rtcNewDevice("threads=1");  // one build thread: the peers are timed on one core
  if (!device) fail(nullptr, "rtcNewDevice");
  device_ = device;
  std::atomic<long long> allocated{0};
  rtcSetDeviceMemoryMonitorFunction(device, count_bytes, &allocated);
  RTCScene scene = rtcNewScene(device);
  if (!scene) fail(device, "rtcNewScene");
  scene_ = scene;
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
  if (!geom) fail(device, "rtcNewGeometry");
  rtcSetGeometryUserPrimitiveCount(geom, static_cast<unsigned>(segs.size()));
  rtcSetGeometryUserData(geom, const_cast<Segments*>(&segs_));
  rtcSetGeometryBoundsFunction(geom, segment_bounds, const_cast<Segments*>(&segs_));
  rtcSetGeometryIntersectFunction(geom, segment_intersect);
  rtcSetGeometryPointQueryFunction(geom, segment_point_query);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) fail(device, "rtcCommitScene");
  rtcSetDeviceMemoryMonitorFunction(device, nullptr, nullptr);
  bytes_ = static_cast<std::size_t>(std::max(0LL, allocated.load())) + segs.size() * sizeof(segs[0]);
}

EmbreeIndex::~EmbreeIndex() {
  if (scene_) rtcReleaseScene(static_cast<RTCScene>(scene_));
  if (device_) rtcReleaseDevice(static_cast<RTCDevice>(device_));
}

PeerHit EmbreeIndex::first_hit(Vec2 a, Vec2 b) const {
  SweepContext ctx;
  rtcInitIntersectContext(&ctx.rtc);
  ctx.a = a;
  ctx.b = b;
  ctx.segs = &segs_;
  RTCRayHit rh{};
  rh.ray.org_x = static_cast<float>(a.x);
  rh.ray.org_y = static_cast<float>(a.y);
  rh.ray.org_z = 0.0f;
  rh.ray.dir_x = static_cast<float>(b.x - a.x);
  rh.ray.dir_y = static_cast<float>(b.y - a.y);
  rh.ray.dir_z = 0.0f;
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = above(1.0);
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(static_cast<RTCScene>(scene_), &ctx.rtc, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  double t = 0.0;
  std::memcpy(&t, &rh.hit.Ng_x, sizeof t);
  return {true, t};
}

double EmbreeIndex::closest_distance(Vec2 p) const {
  PointContext ctx{p, &segs_, std::numeric_limits<double>::infinity()};
  RTCPointQuery q{};
  q.x = static_cast<float>(p.x);
  q.y = static_cast<float>(p.y);
  q.z = 0.0f;
  q.time = 0.0f;
  q.radius = std::numeric_limits<float>::infinity();
  RTCPointQueryContext pctx;
  rtcInitPointQueryContext(&pctx);
  rtcPointQuery(static_cast<RTCScene>(scene_), &q, &pctx, nullptr, &ctx);
  return ctx.best;
}

}  // namespace hk::bench
