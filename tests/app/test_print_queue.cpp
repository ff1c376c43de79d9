// A copy printed through CUPS (copies/print_queue.hpp), against a cupsd the test starts: its own configuration,
// socket and spool in a temporary folder, one raw queue whose backend (a shell script, as CUPS backends may be)
// keeps each job's file. A job arrives whole; a stopped queue, a queue that does not exist and none set each give
// one line and no job. cupsd runs its backends as root here, so the test needs root (CI runs as root); elsewhere,
// or without Debian's cups-daemon, it is skipped with the reason.
#include <cups/cups.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "copies/print_queue.hpp"
#include "copies/tactile_output.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace hk::app {
namespace {

constexpr const char* kCupsd = "/usr/sbin/cupsd";
constexpr const char* kCupsExec = "/usr/lib/cups/daemon/cups-exec";

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// Waits up to `limit` for `done` to hold (polling every 20 ms); true when it did.
template <typename F>
bool wait_for(F done, std::chrono::seconds limit) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

class PrintQueue : public ::testing::Test {
 protected:
  void SetUp() override {
    if (::geteuid() != 0) GTEST_SKIP() << "cupsd runs the test's backend as root: needs root (CI runs as root)";
    if (!fs::exists(kCupsd) || !fs::exists(kCupsExec)) GTEST_SKIP() << "no cupsd here (Debian's cups-daemon)";
    dir_ = fs::temp_directory_path() / ("hk_cups_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    for (const char* sub : {"spool", "cache", "state", "log", "out", "bin/backend", "bin/daemon"})
      fs::create_directories(dir_ / sub);
    fs::permissions(dir_ / "out", fs::perms::all);
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
    // The backend: keeps the job's file as out/job.<id>.pdf (argv[1] is the job id, argv[6] the file).
    const fs::path backend = dir_ / "bin/backend/keep";
    std::ofstream(backend) << "#!/bin/sh\nif [ $# -eq 0 ]; then echo 'direct keep \"Unknown\" \"Keep\"'; exit 0; fi\n"
                              "out=\"${DEVICE_URI#keep:}\"\nif [ -n \"$6\" ]; then cat \"$6\" > \"$out.$1.pdf\"; "
                              "else cat > \"$out.$1.pdf\"; fi\n";
    fs::permissions(backend, fs::perms::owner_all);  // 0700: CUPS runs a backend as root only when it is
    fs::create_symlink(kCupsExec, dir_ / "bin/daemon/cups-exec");
    const std::string conf = (dir_ / "cupsd.conf").string(), files = (dir_ / "cups-files.conf").string();
    const char* argv[] = {kCupsd, "-f", "-c", conf.c_str(), "-s", files.c_str(), nullptr};
    ASSERT_EQ(::posix_spawn(&cupsd_, kCupsd, nullptr, nullptr, const_cast<char**>(argv), environ), 0);
    ASSERT_TRUE(wait_for([&] { return fs::exists(socket_); }, std::chrono::seconds(20)))
        << "cupsd did not start: " << read_file(dir_ / "log/error_log");
    ::setenv("CUPS_SERVER", socket_.c_str(), 1);
    cupsSetServer(socket_.c_str());
    ASSERT_EQ(sh("lpadmin -p kiosk-desk -v keep:" + (dir_ / "out/job").string() + " -E"), 0)
        << read_file(dir_ / "log/error_log");
  }
  void TearDown() override {
    if (cupsd_ > 0) {
      ::kill(cupsd_, SIGTERM);
      ::waitpid(cupsd_, nullptr, 0);
    }
    ::unsetenv("CUPS_SERVER");
    cupsSetServer(nullptr);
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  int sh(const std::string& command) const {
    return std::system(("CUPS_SERVER='" + socket_ + "' " + command + " >/dev/null 2>&1").c_str());
  }
  /// A real copy's PDF.
  fs::path copy_pdf() const {
    TactileGraphic g;
    g.paper = paper_size(Paper::a4);
    g.title = "a test copy";
    g.pages.emplace_back();
    g.pages[0].strokes.push_back({{{20, 20}, {100, 100}}, false, LineStyle::solid, -1});
    const fs::path p = dir_ / "copy.pdf";
    write_tactile(g, p.string(), BrailleGrade::one);
    return p;
  }

  fs::path dir_;
  std::string socket_;
  pid_t cupsd_ = 0;
};

TEST_F(PrintQueue, ACopyArrivesWholeAsOneJob) {
  const fs::path pdf = copy_pdf();
  const PrintOutcome o = print_pdf("kiosk-desk", pdf.string(), "a test copy");
  ASSERT_TRUE(o.queued()) << o.error;
  EXPECT_TRUE(o.error.empty());
  const fs::path job = dir_ / ("out/job." + std::to_string(o.job_id) + ".pdf");
  ASSERT_TRUE(
      wait_for([&] { return fs::exists(job) && fs::file_size(job) == fs::file_size(pdf); }, std::chrono::seconds(30)))
      << read_file(dir_ / "log/error_log");
  EXPECT_EQ(read_file(job), read_file(pdf));
  std::size_t jobs = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "out")) jobs += e.path().extension() == ".pdf";
  EXPECT_EQ(jobs, 1u);
}

TEST_F(PrintQueue, AStoppedQueueAnUnknownOneAndNoneAreEachOneLineAndNoJob) {
  const fs::path pdf = copy_pdf();
  ASSERT_EQ(sh("cupsdisable kiosk-desk"), 0);
  PrintOutcome o = print_pdf("kiosk-desk", pdf.string(), "a test copy");
  EXPECT_FALSE(o.queued());
  EXPECT_NE(o.error.find("printer 'kiosk-desk' is stopped"), std::string::npos) << o.error;
  o = print_pdf("no-such-queue", pdf.string(), "a test copy");
  EXPECT_FALSE(o.queued());
  EXPECT_NE(o.error.find("printer 'no-such-queue' cannot be found"), std::string::npos) << o.error;
  o = print_pdf("", pdf.string(), "a test copy");
  EXPECT_FALSE(o.queued());
  EXPECT_FALSE(o.error.empty());
  for (const std::string& e : {std::string(o.error)}) EXPECT_EQ(e.find('\n'), std::string::npos);
  EXPECT_TRUE(fs::is_empty(dir_ / "out"));
}

}  // namespace
}  // namespace hk::app
