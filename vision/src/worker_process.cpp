// A worker process for a large parser of a stranger's input (see worker_process.hpp).
#include "worker_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

extern char** environ;  // the kiosk's environment, passed on to the worker (sanitizer options)

namespace hk::vision::worker {

bool WireReader::f64(double& v) { return raw(&v, sizeof v) && std::isfinite(v); }

bool WireReader::str(std::string& v, std::uint32_t max) {
  std::uint32_t n = 0;
  if (!u32(n) || n > max || n > left()) return false;
  v.assign(s_.data() + pos_, n);
  pos_ += n;
  return true;
}

bool WireReader::raw(void* p, std::size_t n) {
  if (n > left()) return false;
  std::memcpy(p, s_.data() + pos_, n);
  pos_ += n;
  return true;
}

void write_all(int fd, const std::string& s) {
  std::size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::write(fd, s.data() + off, s.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // the parent gave up on us; nothing else to do
    off += static_cast<std::size_t>(n);
  }
}

void confine_worker(double cpu_s, double max_memory_mb) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  ::syscall(SYS_close_range, static_cast<unsigned>(kInputFd), static_cast<unsigned>(kAnswerFd - 1), 0u);
  ::syscall(SYS_close_range, static_cast<unsigned>(kAnswerFd + 1), ~0u, 0u);
  const int devnull = ::open("/dev/null", O_RDWR | O_CLOEXEC);
  if (devnull >= 0) {
    ::dup2(devnull, STDOUT_FILENO);
#if !defined(HK_WORKER_ASAN)
    ::dup2(devnull, STDERR_FILENO);  // sanitizer builds keep stderr, so a sanitizer report in the worker is seen
#endif
    if (devnull > STDERR_FILENO) ::close(devnull);
  }
  const auto cpu = static_cast<rlim_t>(std::ceil(std::max(cpu_s, 0.001)));
  const rlimit cpu_limit{cpu, cpu + 1};  // SIGXCPU at the soft limit, SIGKILL a second later
  ::setrlimit(RLIMIT_CPU, &cpu_limit);
#if !defined(HK_WORKER_ASAN)
  if (max_memory_mb > 0) {
    long pages = 0;
    if (FILE* f = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
      std::fclose(f);
    }
    const double inherited = static_cast<double>(pages) * static_cast<double>(::sysconf(_SC_PAGESIZE));
    const auto as = static_cast<rlim_t>(inherited + max_memory_mb * 1048576.0);
    const rlimit as_limit{as, as};
    ::setrlimit(RLIMIT_AS, &as_limit);
  }
#else
  (void)max_memory_mb;
#endif
}

void crash_on_purpose() {
  ::signal(SIGSEGV, SIG_DFL);
  ::raise(SIGSEGV);
  ::_exit(98);
}

void hang_on_purpose() {
  volatile unsigned long spin = 0;
  for (;;) spin = spin + 1;
}

std::span<const std::uint8_t> map_input(std::size_t size) {
  struct stat st {};
  if (::fstat(kInputFd, &st) != 0 || static_cast<std::size_t>(st.st_size) != size || size == 0) return {};
  void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, kInputFd, 0);
  if (map == MAP_FAILED) return {};
  return {static_cast<const std::uint8_t*>(map), size};
}

std::string find_worker(const char* env_var, const char* file_name, const char* built_path) {
  if (const char* env = std::getenv(env_var); env && *env) return std::string(env);
  char self[4096];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  if (n > 0) {
    std::string beside(self, static_cast<std::size_t>(n));
    beside = beside.substr(0, beside.rfind('/') + 1) + file_name;
    if (::access(beside.c_str(), X_OK) == 0) return beside;
  }
  return built_path;
}

std::string arg(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

namespace {

/// A descriptor moved to 10 or above (so dup2 onto 3 and 4 in the child never meets it), close-on-exec.
int high_fd(int fd) {
  const int h = ::fcntl(fd, F_DUPFD_CLOEXEC, 10);
  ::close(fd);
  return h;
}

[[noreturn]] void cannot_start(const char* what, int e) {
  throw WorkerStartFailure{std::string(what) + ": " + std::strerror(e)};
}

/// The input in memory the worker maps read-only (sealed: it cannot be changed after it is written).
int sealed_input(std::span<const std::uint8_t> input) {
  const int fd = high_fd(::memfd_create("hk-worker-input", MFD_CLOEXEC | MFD_ALLOW_SEALING));
  if (fd < 0) cannot_start("memfd", errno);
  std::size_t off = 0;
  while (off < input.size()) {
    const ssize_t n = ::write(fd, input.data() + off, input.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int e = errno;
      ::close(fd);
      cannot_start("memfd write", e);
    }
    off += static_cast<std::size_t>(n);
  }
  ::fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_WRITE | F_SEAL_SEAL);
  return fd;
}

/// Reads `fd` into run.answer until EOF, the deadline, max_answer bytes or the cancel flag.
void read_answer(int fd, std::chrono::steady_clock::time_point deadline, std::size_t max_answer,
                 const std::atomic<bool>* cancel, const AnswerSoFar& on_data, WorkerRun& run) {
  char buf[1 << 16];
  for (;;) {
    if (cancel && cancel->load(std::memory_order_relaxed)) {
      run.cancelled = true;
      return;
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      run.timed_out = true;
      return;
    }
    pollfd p{fd, POLLIN, 0};
    const long long slice = cancel ? std::min<long long>(left, kCancelPoll_ms) : std::min<long long>(left, INT_MAX);
    const int rc = ::poll(&p, 1, static_cast<int>(slice));
    if (rc < 0 && errno == EINTR) continue;
    if (rc < 0) return;
    if (rc == 0) continue;  // the loop head sees the deadline and the flag
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) return;  // EOF: the worker has finished or died
    if (run.answer.size() + static_cast<std::size_t>(n) > max_answer) {
      run.overflow = true;
      return;
    }
    run.answer.append(buf, static_cast<std::size_t>(n));
    if (on_data) on_data(run.answer);
  }
}

}  // namespace

WorkerRun run_worker(const std::string& path, const std::vector<std::string>& args, std::span<const std::uint8_t> input,
                     double wall_s, std::size_t max_answer, const std::atomic<bool>* cancel,
                     const AnswerSoFar& on_data) {
  const int in = sealed_input(input);
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    const int e = errno;
    ::close(in);
    cannot_start("pipe", e);
  }
  fds[0] = high_fd(fds[0]);
  fds[1] = high_fd(fds[1]);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, in, kInputFd);
  posix_spawn_file_actions_adddup2(&fa, fds[1], kAnswerFd);
  std::vector<std::string> all{path};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  pid_t pid = -1;
  const int rc = ::posix_spawn(&pid, path.c_str(), &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  ::close(in);
  ::close(fds[1]);
  if (rc != 0) {
    ::close(fds[0]);
    cannot_start(path.c_str(), rc);
  }
  WorkerRun run;
  read_answer(
      fds[0],
      t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(wall_s)),
      max_answer, cancel, on_data, run);
  ::kill(pid, SIGKILL);  // in every case: a worker that closed its pipe but lives on is not left behind
  ::close(fds[0]);
  rusage ru{};
  while (::wait4(pid, &run.status, 0, &ru) < 0 && errno == EINTR) {
  }
  run.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  run.max_rss_kb = ru.ru_maxrss;
  run.cpu_s = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
              1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  return run;
}

}  // namespace hk::vision::worker
