// Fuzz harness: what a pantograph board (or anything pretending to be one on the serial line) sends back
// (haptics/include/haptics/hapi_protocol.hpp, haptics/include/haptics/io/haply_device.hpp).
//
// Input: byte 0 picks a board layout (device id, encoder count and ports); the rest is the byte stream
// from the board. Two entry points:
//  1. hapi::decode_reply on that layout, at every offset of the stream (as the driver resynchronises),
//     checked against an independent decoding: Ok only with the right id, finite angles within 1e5 deg
//     written to exactly the slots of the layout's encoder indices; other slots untouched; Short/WrongId/
//     NonFinite/OutOfRange exactly when they apply;
//  2. io::HaplyDevice (the driver) over a fake transport that answers open() with one valid reply and then
//     hands over the stream in chunks whose sizes come from the end of the input, one chunk per servo
//     tick (read + write_force): the status stays Ok or Lost, the handle position and the joint angles
//     stay finite, the torques sent stay finite and within the torque limit, and the counters add up.

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "haptics/hapi_protocol.hpp"
#include "haptics/io/byte_transport.hpp"
#include "haptics/io/haply_device.hpp"
#include "kinematics/haply_mechanism.hpp"
#include "kinematics/pantograph.hpp"

namespace {

using namespace hk::hapi;

/// Layout from one byte: bits 0-2 encoder count (0..4, 5-7 -> 2), bits 3-4 a rotation of the ports,
/// bits 5-7 the device id (1..8).
BoardLayout layout_from(std::uint8_t b) {
  BoardLayout l = BoardLayout::haply_gen3();
  l.encoder_count = (b & 7) <= 4 ? (b & 7) : 2;
  const int rot = (b >> 3) & 3;
  for (int i = 0; i < 4; ++i) {
    l.encoders[i].index = i + 1;
    l.encoders[i].port = (i + rot) % 4 + 1;
  }
  l.device_id = static_cast<std::uint8_t>(((b >> 5) & 7) + 1);
  return l;
}

void check_decode(const BoardLayout& l, const std::uint8_t* in, int n) {
  const int len = reply_length(l);
  FUZZ_CHECK(len >= 1 && len <= kMaxPacketBytes, std::to_string(len));
  double angle[4] = {-7777, -7777, -7777, -7777};
  const ReplyStatus st = decode_reply(l, in, n, angle);
  // Independent decoding.
  ReplyStatus want = ReplyStatus::Ok;
  double expect[4] = {-7777, -7777, -7777, -7777};
  if (n < len) {
    want = ReplyStatus::Short;
  } else if (in[0] != l.device_id) {
    want = ReplyStatus::WrongId;
  } else {
    int k = 1;
    for (int port = 1; port <= 4 && want == ReplyStatus::Ok; ++port) {
      for (int i = 0; i < l.encoder_count; ++i) {
        if (l.encoders[i].port != port) continue;
        float f;
        std::uint32_t bits = static_cast<std::uint32_t>(in[k]) | (static_cast<std::uint32_t>(in[k + 1]) << 8) |
                             (static_cast<std::uint32_t>(in[k + 2]) << 16) |
                             (static_cast<std::uint32_t>(in[k + 3]) << 24);
        std::memcpy(&f, &bits, 4);
        k += 4;
        if (!std::isfinite(f)) {
          want = ReplyStatus::NonFinite;
        } else if (std::fabs(f) > 1e5) {
          want = ReplyStatus::OutOfRange;
        } else {
          expect[l.encoders[i].index - 1] = f;
        }
        break;
      }
    }
  }
  FUZZ_CHECK(st == want, std::to_string(static_cast<int>(st)) + " != " + std::to_string(static_cast<int>(want)));
  for (int i = 0; i < 4; ++i) {
    const double got = angle[i];
    if (st != ReplyStatus::Ok) {
      FUZZ_CHECK(got == -7777, "written although not Ok");
    } else {
      FUZZ_CHECK(got == expect[i], std::to_string(i) + ": " + std::to_string(got) + " vs " + std::to_string(expect[i]));
      FUZZ_CHECK(got == -7777 || (std::isfinite(got) && std::fabs(got) <= 1e5), std::to_string(got));
    }
  }
}

/// The board side of the serial line: one valid reply for open(), then the fuzz stream chunk by chunk.
class FakeBoard final : public hk::io::ByteTransport {
 public:
  FakeBoard(std::vector<std::uint8_t> hello, const std::vector<std::uint8_t>* stream)
      : pending_(std::move(hello)), stream_(stream) {}
  void open() override { open_ = true; }
  void close() noexcept override { open_ = false; }
  int write(const std::uint8_t* data, int n, int) noexcept override {
    if (!open_) return kGone;
    FUZZ_CHECK(n >= 2 && n <= kMaxPacketBytes, std::to_string(n));
    if (data[0] == 0x02) {  // a torque packet: every float finite and within the limit
      for (int k = 2; k + 4 <= n; k += 4) {
        const float t = get_f32_le(data + k);
        FUZZ_CHECK(std::isfinite(t) && std::fabs(t) <= kTorqueLimit * (1 + 1e-6), std::to_string(t));
      }
    }
    return n;
  }
  int read(std::uint8_t* buf, int capacity, int) noexcept override {
    if (!open_) return kGone;
    const int n = std::min<int>(capacity, static_cast<int>(pending_.size() - at_));
    std::memcpy(buf, pending_.data() + at_, static_cast<std::size_t>(n));
    at_ += static_cast<std::size_t>(n);
    return n;
  }
  void flush_input() noexcept override {}
  bool is_open() const noexcept override { return open_; }
  std::string name() const override { return "fuzz board"; }

  /// The next `n` bytes of the stream become readable.
  void deliver(std::size_t n) {
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(at_));
    at_ = 0;
    n = std::min(n, stream_->size() - sent_);
    pending_.insert(pending_.end(), stream_->begin() + static_cast<std::ptrdiff_t>(sent_),
                    stream_->begin() + static_cast<std::ptrdiff_t>(sent_ + n));
    sent_ += n;
  }
  bool done() const { return sent_ == stream_->size(); }

  static constexpr double kTorqueLimit = 0.123;

 private:
  std::vector<std::uint8_t> pending_;
  std::size_t at_ = 0;
  const std::vector<std::uint8_t>* stream_;
  std::size_t sent_ = 0;
  bool open_ = false;
};

void check_device(const BoardLayout& board_layout, const std::vector<std::uint8_t>& stream,
                  FuzzedDataProvider& chunks) {
  hk::io::HaplyDeviceParams p;
  p.layout = BoardLayout::haply_gen3();
  p.layout.device_id = board_layout.device_id;
  p.open_timeout_ms = 50;
  p.reopen_interval_s = 100.0;  // no re-open during a run
  p.torque_limit_n_m = FakeBoard::kTorqueLimit;
  // A valid first reply: the handle at the centre of the usable rectangle.
  hk::JointAngles q;
  FUZZ_CHECK(hk::inverse_kinematics(geometry_of(p.mechanism), p.rect_center_device_m, &q), "");
  double a1 = 0, a2 = 0;
  haply_deg_from_joints(q, &a1, &a2);
  std::vector<std::uint8_t> hello(9);
  hello[0] = p.layout.device_id;
  put_f32_le(static_cast<float>(a2), hello.data() + 1);  // gen3: port 1 carries encoder 2
  put_f32_le(static_cast<float>(a1), hello.data() + 5);

  FakeBoard* board = nullptr;
  hk::io::HaplyDevice dev(p, [&]() -> std::unique_ptr<hk::io::ByteTransport> {
    auto b = std::make_unique<FakeBoard>(hello, &stream);
    board = b.get();
    return b;
  });
  dev.open();
  FUZZ_CHECK(dev.status() == hk::DeviceStatus::Ok, "");
  // A tick may deliver nothing (a missing reply); once the sizes run out, a reply's length per tick.
  const int max_ticks = 8 + 2 * static_cast<int>(stream.size());
  for (int tick = 0; tick < max_ticks && !board->done(); ++tick) {
    board->deliver(chunks.remaining_bytes() > 0 ? chunks.ConsumeIntegralInRange<std::size_t>(0, 40) : 9);
    const hk::DeviceSample s = dev.read();
    FUZZ_CHECK(s.status == hk::DeviceStatus::Ok || s.status == hk::DeviceStatus::Lost, std::to_string(tick));
    FUZZ_CHECK(std::isfinite(s.handle_m.x) && std::isfinite(s.handle_m.y), std::to_string(tick));
    double th1 = 0, th2 = 0;
    dev.joint_angles_deg(&th1, &th2);
    FUZZ_CHECK(std::isfinite(th1) && std::isfinite(th2) && std::fabs(th1) <= 1e5 && std::fabs(th2) <= 1e5,
               std::to_string(th1));
    dev.write_force(
        {chunks.ConsumeFloatingPointInRange<double>(-50, 50), chunks.ConsumeFloatingPointInRange<double>(-50, 50)});
    double t1 = 0, t2 = 0;
    dev.last_torques_n_m(&t1, &t2);
    FUZZ_CHECK(std::isfinite(t1) && std::isfinite(t2) && std::fabs(t1) <= p.torque_limit_n_m &&
                   std::fabs(t2) <= p.torque_limit_n_m,
               std::to_string(t1));
    const hk::io::HaplyCounters c = dev.counters();
    FUZZ_CHECK(c.replies >= 1 && c.replies <= 1 + static_cast<std::int64_t>(stream.size()) / 9,
               std::to_string(c.replies));
    FUZZ_CHECK(c.malformed <= static_cast<std::int64_t>(stream.size()), std::to_string(c.malformed));
    // A packet's reply is waited for at most kReplyWaitTicks reads (the writes between are skipped).
    FUZZ_CHECK(c.replies_missing <= hk::io::kReplyWaitTicks * (c.ticks + 1), std::to_string(c.replies_missing));
    FUZZ_CHECK(c.writes_skipped <= tick + 1, std::to_string(c.writes_skipped));
  }
  dev.close();
  FUZZ_CHECK(dev.status() == hk::DeviceStatus::Closed, "");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const BoardLayout l = layout_from(data[0]);
  validate(l);  // every layout made by layout_from is valid
  // 1. The decoder at every offset (as the driver's resynchronisation tries them).
  const int n = static_cast<int>(std::min<std::size_t>(size - 1, 1 << 16));
  for (int at = 0; at <= n; ++at) check_decode(l, data + 1 + at, n - at);

  // 2. The driver: the first half of the rest is the stream, the end feeds chunk sizes and forces.
  FuzzedDataProvider fdp(data + 1, size - 1);
  const std::vector<std::uint8_t> stream =
      fdp.ConsumeBytes<std::uint8_t>(std::min<std::size_t>(4096, (size - 1) / 2 + 1));
  check_device(l, stream, fdp);
  return 0;
}
