#pragma once
/// @file worker_process.hpp
/// Running a large parser of a stranger's input (poppler, Tesseract) in a worker process: the kiosk starts
/// the worker executable with posix_spawn(3) (no fork of a process whose other threads may hold locks), the
/// input in a sealed memfd as descriptor 3, the answer pipe as descriptor 4 and the request in argv. The
/// worker confines itself (confine_worker), does its work, writes one answer and leaves with _exit. The
/// parent reads the answer with poll(2) against a wall-clock deadline, SIGKILLs the worker in every case and
/// reaps it with wait4(2) for its CPU time and peak memory. Answers are a small binary format written with
/// WireWriter and read with WireReader, every size checked before anything is allocated; numbers are in the
/// machine's byte order (the worker runs on the same machine). Private to vision.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <new>
#include <span>
#include <string>
#include <utility>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#define HK_WORKER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define HK_WORKER_ASAN 1
#endif
#endif

namespace hk::vision::worker {

/// The worker's descriptors: its input (a sealed memfd, mapped read-only) and its answer pipe.
inline constexpr int kInputFd = 3;
inline constexpr int kAnswerFd = 4;

/// Builds an answer.
class WireWriter {
 public:
  void u8(std::uint8_t v) { buf_.push_back(static_cast<char>(v)); }
  void u32(std::uint32_t v) { raw(&v, sizeof v); }
  void i32(std::int32_t v) { raw(&v, sizeof v); }
  void f64(double v) { raw(&v, sizeof v); }
  /// u32 length, then the bytes.
  void str(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size()));
    buf_.append(s);
  }
  void raw(const void* p, std::size_t n) { buf_.append(static_cast<const char*>(p), n); }
  const std::string& bytes() const { return buf_; }

 private:
  std::string buf_;
};

/// Reads an answer; every read returns false (taking nothing) when the answer is too short or a size is over
/// its bound, so a malformed answer is refused, never trusted.
class WireReader {
 public:
  explicit WireReader(const std::string& s) : s_(s) {}
  bool u8(std::uint8_t& v) { return raw(&v, 1); }
  bool u32(std::uint32_t& v) { return raw(&v, sizeof v); }
  bool i32(std::int32_t& v) { return raw(&v, sizeof v); }
  /// A finite double.
  bool f64(double& v);
  /// A string of at most `max` bytes.
  bool str(std::string& v, std::uint32_t max);
  bool raw(void* p, std::size_t n);
  std::size_t left() const { return s_.size() - pos_; }

 private:
  const std::string& s_;
  std::size_t pos_ = 0;
};

/// Worker side: the whole answer of a worker: u32 `magic`, then u8 0 and what `work(WireWriter&)` wrote, or
/// u8 1, u8 kind and the problem (str) when it fails: a thrown `Refusal` (a type with `kind`, an enum, and
/// `problem`, a string) as it says, std::bad_alloc as `out_of_memory`, anything else as `failed`.
template <class Refusal, class Kind, class Work>
WireWriter worker_answer(std::uint32_t magic, Work&& work, std::pair<Kind, std::string> out_of_memory,
                         std::pair<Kind, std::string> failed) {
  WireWriter out;
  out.u32(magic);
  auto refuse = [&out](Kind kind, const std::string& problem) {
    out.u8(1);
    out.u8(static_cast<std::uint8_t>(kind));
    out.str(problem);
  };
  try {
    WireWriter answer;
    work(answer);
    out.u8(0);
    out.raw(answer.bytes().data(), answer.bytes().size());
  } catch (const Refusal& r) {
    refuse(r.kind, r.problem);
  } catch (const std::bad_alloc&) {
    refuse(out_of_memory.first, out_of_memory.second);
  } catch (...) {
    refuse(failed.first, failed.second);
  }
  return out;
}

/// Worker side: writes all of `s` to `fd` (gives up silently when the parent is gone).
void write_all(int fd, const std::string& s);

/// Worker side, first thing after the input is mapped: asks to be killed with the kiosk (PR_SET_PDEATHSIG),
/// closes every descriptor but kAnswerFd (what the input turns into finds no kiosk file, socket or device),
/// sends stdout (and stderr, but in sanitizer builds, so a sanitizer's report is seen) to /dev/null, and sets
/// RLIMIT_CPU to `cpu_s` (SIGXCPU, SIGKILL a second later) and, but in sanitizer builds (ASan reserves
/// terabytes of shadow memory), RLIMIT_AS to its present size plus `max_memory_mb` (0: no limit).
void confine_worker(double cpu_s, double max_memory_mb);

/// Worker side, test hooks (a worker that fails on purpose, so that tests of crashes and hangs need no
/// special input): dies of SIGSEGV with the default action (not a sanitizer's handler, as an unsanitized
/// crash would).
[[noreturn]] void crash_on_purpose();
/// Spins on the CPU until a limit stops it.
[[noreturn]] void hang_on_purpose();

/// Worker side: maps descriptor kInputFd, which must hold exactly `size` > 0 bytes, read-only. Empty span on
/// failure.
std::span<const std::uint8_t> map_input(std::size_t size);

/// What a run of a worker gave.
struct WorkerRun {
  std::string answer;      ///< bytes read from the pipe
  bool timed_out = false;  ///< the wall-clock deadline passed
  bool overflow = false;   ///< the worker sent more than max_answer
  bool cancelled = false;  ///< the caller's cancel flag was raised (checked every kCancelPoll_ms)
  int status = 0;          ///< from wait4
  double cpu_s = 0.0;      ///< user + system time of the worker [s]
  double ms = 0.0;         ///< wall time [ms]
  long max_rss_kb = 0;     ///< peak resident memory [KiB]
};

/// The worker could not be started (memfd, pipe or posix_spawn failed): `why` says which and errno's words.
struct WorkerStartFailure {
  std::string why;
};

/// How often run_worker looks at its cancel flag while it waits for the answer [ms].
inline constexpr int kCancelPoll_ms = 50;

/// Called on run_worker's thread each time more of the answer has come: the answer so far (a worker that sends
/// its answer in records as it works lets the caller use each before the last).
using AnswerSoFar = std::function<void(const std::string& answer)>;

/// Parent side: runs the worker executable `path` with `args` (argv[1..]) on `input`, reads its answer until
/// EOF, `wall_s` [s], `max_answer` bytes or `*cancel` (when given) becoming true, then kills and reaps it.
/// `on_data`, when given, sees the answer after each read. The kiosk's environment is passed on (sanitizer
/// options). Blocks the calling thread for at most about wall_s (kCancelPoll_ms after a cancel), plus what
/// on_data takes.
/// @throws WorkerStartFailure when it cannot be started.
WorkerRun run_worker(const std::string& path, const std::vector<std::string>& args, std::span<const std::uint8_t> input,
                     double wall_s, std::size_t max_answer, const std::atomic<bool>* cancel = nullptr,
                     const AnswerSoFar& on_data = {});

/// The worker executable: $`env_var` if set; else `file_name` beside this executable (an installed kiosk);
/// else `built_path` (tests and bench binaries live elsewhere in the build tree).
std::string find_worker(const char* env_var, const char* file_name, const char* built_path);

/// `v` printed with every digit ("%.17g"), for argv.
std::string arg(double v);

}  // namespace hk::vision::worker
