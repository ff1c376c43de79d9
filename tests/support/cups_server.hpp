#pragma once
// A cupsd of the test's own: its configuration, socket and spool in a temporary folder, one raw queue whose
// backend (a shell script, as CUPS backends may be) keeps each job's file as out/job.<id>.pdf. libcups in this
// process is pointed at it (CUPS_SERVER and cupsSetServer). cupsd runs that backend as root, so it needs root
// (CI runs as root) and Debian's cups-daemon; start() says why not otherwise.
#include <cups/cups.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

extern char** environ;

namespace hk::test {

class CupsServer {
 public:
  static constexpr const char* kQueue = "kiosk-desk";

  ~CupsServer() { stop(); }

  /// Starts cupsd and adds the queue; "" when it runs, else why it cannot here (for GTEST_SKIP) or what failed.
  std::string start() {
    namespace fs = std::filesystem;
    if (::geteuid() != 0) return "cupsd runs the test's backend as root: needs root (CI runs as root)";
    if (!fs::exists(kCupsd) || !fs::exists(kCupsExec)) return "no cupsd here (Debian's cups-daemon)";
    dir_ = fs::temp_directory_path() / ("hk_cups_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    for (const char* sub : {"spool", "cache", "state", "log", "out", "bin/backend", "bin/daemon"})
      fs::create_directories(dir_ / sub);
    socket_ = (dir_ / "cups.sock").string();
    std::ofstream(dir_ / "cupsd.conf")
        << "Listen " << socket_ << "\nLogLevel warn\nWebInterface No\nBrowsing No\n"
        << "<Location />\n  Order allow,deny\n  Allow all\n</Location>\n"
        << "<Policy default>\n  <Limit All>\n    Order deny,allow\n  </Limit>\n</Policy>\n";
    std::ofstream(dir_ / "cups-files.conf")
        << "ServerRoot " << dir_.string() << "\nServerBin " << (dir_ / "bin").string() << "\nRequestRoot "
        << (dir_ / "spool").string() << "\nCacheDir " << (dir_ / "cache").string() << "\nStateDir "
        << (dir_ / "state").string() << "\nTempDir " << (dir_ / "spool").string() << "\nErrorLog "
        << (dir_ / "log/error_log").string() << "\nAccessLog " << (dir_ / "log/access_log").string() << "\nPageLog "
        << (dir_ / "log/page_log").string() << "\n";
    const fs::path backend = dir_ / "bin/backend/keep";
    std::ofstream(backend) << "#!/bin/sh\nif [ $# -eq 0 ]; then echo 'direct keep \"Unknown\" \"Keep\"'; exit 0; fi\n"
                              "out=\"${DEVICE_URI#keep:}\"\nif [ -n \"$6\" ]; then cat \"$6\" > \"$out.$1.pdf\"; "
                              "else cat > \"$out.$1.pdf\"; fi\n";
    fs::permissions(backend, fs::perms::owner_all);  // 0700: CUPS runs a backend as root only when it is
    fs::create_symlink(kCupsExec, dir_ / "bin/daemon/cups-exec");
    const std::string conf = (dir_ / "cupsd.conf").string(), files = (dir_ / "cups-files.conf").string();
    const char* argv[] = {kCupsd, "-f", "-c", conf.c_str(), "-s", files.c_str(), nullptr};
    if (::posix_spawn(&pid_, kCupsd, nullptr, nullptr, const_cast<char**>(argv), environ) != 0) {
      pid_ = 0;
      return "cupsd could not be started";
    }
    if (!wait_for([&] { return fs::exists(socket_); }, std::chrono::seconds(20)))
      return "cupsd did not start: " + log();
    ::setenv("CUPS_SERVER", socket_.c_str(), 1);
    cupsSetServer(socket_.c_str());
    if (sh(std::string("lpadmin -p ") + kQueue + " -v keep:" + (dir_ / "out/job").string() + " -E") != 0)
      return "lpadmin failed: " + log();
    return {};
  }

  void stop() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
      pid_ = 0;
      ::unsetenv("CUPS_SERVER");
      cupsSetServer(nullptr);
    }
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
    dir_.clear();
  }

  /// Runs `command` against this cupsd (lpadmin, cupsdisable, ...); its exit status.
  int sh(const std::string& command) const {
    return std::system(("CUPS_SERVER='" + socket_ + "' " + command + " >/dev/null 2>&1").c_str());
  }
  /// Where the queue's backend keeps each job: job.<id>.pdf.
  std::filesystem::path out() const { return dir_ / "out"; }
  std::filesystem::path dir() const { return dir_; }
  /// The file job `id` was kept as.
  std::filesystem::path job_file(int id) const { return out() / ("job." + std::to_string(id) + ".pdf"); }
  /// cupsd's error log.
  std::string log() const {
    std::ifstream f(dir_ / "log/error_log");
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }

  /// Waits up to `limit` for `done` to hold (polling every 20 ms); true when it did.
  template <typename F>
  static bool wait_for(F done, std::chrono::seconds limit) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (!done()) {
      if (std::chrono::steady_clock::now() > until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
  }

 private:
  static constexpr const char* kCupsd = "/usr/sbin/cupsd";
  static constexpr const char* kCupsExec = "/usr/lib/cups/daemon/cups-exec";
  std::filesystem::path dir_;
  std::string socket_;
  pid_t pid_ = 0;
};

}  // namespace hk::test
