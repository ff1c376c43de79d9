#pragma once
// Runs part of a test in a forked child (a private mount namespace, capabilities dropped, ...), so what it
// changes about the process never reaches the test process; the child reports back one string.
#include <sys/wait.h>
#include <unistd.h>

#include <exception>
#include <functional>
#include <string>

namespace hk::test {

/// Forks; the child runs `work` (an exception becomes "exception: <what>"), writes what it returns to a
/// pipe and exits. Returns that string ("" = passed, by the callers' convention), with " (child ended
/// with status N)" appended when the child did not exit 0, or `no_child` when no pipe or child could be
/// made. Call from a single-threaded point of the test (fork copies only the calling thread).
inline std::string run_in_child(const std::function<std::string()>& work, const std::string& no_child) {
  int fds[2];
  if (::pipe(fds) != 0) return no_child;
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return no_child;
  }
  if (pid == 0) {
    ::close(fds[0]);
    std::string r;
    try {
      r = work();
    } catch (const std::exception& e) {
      r = std::string("exception: ") + e.what();
    }
    if (::write(fds[1], r.data(), r.size()) < 0) ::_exit(3);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string out;
  char buf[512];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    out += " (child ended with status " + std::to_string(status) + ")";
  return out;
}

}  // namespace hk::test
