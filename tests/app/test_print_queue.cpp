// A copy printed through CUPS (copies/print_queue.hpp), against a cupsd the test starts (cups_server.hpp): a job
// arrives whole; a stopped queue, a queue that does not exist and none set each give one line and no job. Needs
// root and Debian's cups-daemon (CI has both); skipped with the reason elsewhere.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "copies/print_queue.hpp"
#include "copies/tactile_output.hpp"
#include "cups_server.hpp"

namespace fs = std::filesystem;

namespace hk::app {
namespace {

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

class PrintQueue : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = cups_.start();
    if (!why.empty()) GTEST_SKIP() << why;
  }
  /// A real copy's PDF.
  fs::path copy_pdf() const {
    TactileGraphic g;
    g.paper = paper_size(Paper::a4);
    g.title = "a test copy";
    g.pages.emplace_back();
    g.pages[0].strokes.push_back({{{20, 20}, {100, 100}}, false, LineStyle::solid, -1});
    const fs::path p = cups_.dir() / "copy.pdf";
    write_tactile(g, p.string(), BrailleGrade::one);
    return p;
  }
  hk::test::CupsServer cups_;
};

TEST_F(PrintQueue, ACopyArrivesWholeAsOneJob) {
  const fs::path pdf = copy_pdf();
  const PrintOutcome o = print_pdf(hk::test::CupsServer::kQueue, pdf.string(), "a test copy");
  ASSERT_TRUE(o.queued()) << o.error;
  EXPECT_TRUE(o.error.empty());
  const fs::path job = cups_.job_file(o.job_id);
  ASSERT_TRUE(hk::test::CupsServer::wait_for(
      [&] { return fs::exists(job) && fs::file_size(job) == fs::file_size(pdf); }, std::chrono::seconds(30)))
      << cups_.log();
  EXPECT_EQ(read_file(job), read_file(pdf));
  std::size_t jobs = 0;
  for (const auto& e : fs::directory_iterator(cups_.out())) jobs += e.path().extension() == ".pdf";
  EXPECT_EQ(jobs, 1u);
}

TEST_F(PrintQueue, AStoppedQueueAnUnknownOneAndNoneAreEachOneLineAndNoJob) {
  const fs::path pdf = copy_pdf();
  ASSERT_EQ(cups_.sh(std::string("cupsdisable ") + hk::test::CupsServer::kQueue), 0);
  PrintOutcome o = print_pdf(hk::test::CupsServer::kQueue, pdf.string(), "a test copy");
  EXPECT_FALSE(o.queued());
  EXPECT_NE(o.error.find("printer 'kiosk-desk' is stopped"), std::string::npos) << o.error;
  o = print_pdf("no-such-queue", pdf.string(), "a test copy");
  EXPECT_FALSE(o.queued());
  EXPECT_NE(o.error.find("printer 'no-such-queue' cannot be found"), std::string::npos) << o.error;
  EXPECT_EQ(o.error.find('\n'), std::string::npos);
  o = print_pdf("", pdf.string(), "a test copy");
  EXPECT_FALSE(o.queued());
  EXPECT_FALSE(o.error.empty());
  EXPECT_TRUE(fs::is_empty(cups_.out()));
}

}  // namespace
}  // namespace hk::app
