#pragma once
/// @file without_file_override.hpp
/// Runs a step of a test as the file system treats an unprivileged user, also when the test runs as root
/// (CI does): on a thread of its own whose effective capabilities lack CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH
/// and CAP_FOWNER, so a mode-0555 folder refuses a write as it does for the kiosk's service user.
/// Capabilities are per thread on Linux (capset(2) on the calling thread), so the rest of the test process
/// keeps its own. Without root the thread has none of them to drop and runs the step as it is.

#include <linux/capability.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <future>
#include <stdexcept>
#include <thread>
#include <utility>

namespace hk::test {

/// Takes CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH and CAP_FOWNER out of the calling thread's effective set.
/// Returns false when the kernel refused either call.
inline bool drop_file_override_on_this_thread() {
  __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
  __user_cap_data_struct data[2] = {};
  if (::syscall(SYS_capget, &header, data) != 0) return false;
  for (const int cap : {CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH, CAP_FOWNER}) {
    data[cap / 32].effective &= ~(1u << (cap % 32));
  }
  return ::syscall(SYS_capset, &header, data) == 0;
}

/// Calls `f()` on a new thread without the file-mode override and returns its result (rethrowing what it
/// threw). @throws std::runtime_error when the capabilities could not be dropped.
template <class F>
auto without_file_override(F&& f) -> decltype(f()) {
  using Result = decltype(f());
  std::packaged_task<Result()> task([&f]() -> Result {
    if (!drop_file_override_on_this_thread()) throw std::runtime_error("capset refused to drop CAP_DAC_OVERRIDE");
    return f();
  });
  std::future<Result> result = task.get_future();
  std::thread worker(std::move(task));
  worker.join();
  return result.get();
}

}  // namespace hk::test
