// Inputs the fuzz harnesses (fuzz/fuzz_image.cpp, fuzz_pdf.cpp; scripts/fuzz.sh) found breaking a property, kept in
// tests/data/fuzz/<harness>/ and fed through the same entry points: each must be refused with a one-line
// error naming the input (or read correctly).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_inputs.hpp"
#include "vision/intake.hpp"
#include "vision/pdf.hpp"

namespace hk::vision {
namespace {

namespace fs = std::filesystem;
using test::is_one_line;
using test::kept_inputs;
using test::read_bytes;

/// what() of the InputError decode_image must throw for `file` (named "stick/<file>").
std::string image_refusal(const fs::path& file) {
  try {
    (void)decode_image(read_bytes(file), "stick/" + file.filename().string(), ImageLimits{});
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " was decoded";
  return {};
}

TEST(ImageFuzzRegressions, EveryKeptInputIsRefusedOnOneLine) {
  const std::vector<fs::path> files = kept_inputs("image");
  ASSERT_FALSE(files.empty());
  for (const fs::path& p : files) {
    const std::string what = image_refusal(p);
    EXPECT_TRUE(is_one_line(what)) << p << ": " << what;
    EXPECT_EQ(what.rfind("image 'stick/" + p.filename().string() + "': ", 0), 0u) << what;
  }
}

TEST(ImageFuzzRegressions, PngChunkTypeOfControlBytesIsEscaped) {
  // IHDR, then a chunk header whose length runs past the end and whose type is "@\x0F\x84\x18": the message
  // quoted the 4 type bytes raw (a control character and a stray UTF-8 byte in the kiosk's log line).
  const std::string what = image_refusal(test::fuzz_dir("image") / "png_chunk_type_control_bytes.png");
  EXPECT_NE(what.find("truncated PNG: chunk '@\\x0F\\x84\\x18' at byte 33 runs past the end of the file"),
            std::string::npos)
      << what;
}

TEST(PdfFuzzRegressions, EveryKeptInputEndsWithinTheWorkerLimits) {
  // poppler 22.12 (not our code) is slow on some of these: huge_xref_subsection.pdf, a 4 KB file whose xref
  // subsection starts at object 85000000000000000000000..., makes it build and copy enormous tables (3.5 s
  // and 300 MB in pdftoppm; over 10 s in the fuzz harness, which runs poppler in-process under ASan).
  // The kiosk never runs poppler in its own process: the worker's CPU and wall-clock limits end it, and the
  // visitor gets a one-line PdfError (or the page, on a machine fast enough).
  PdfLimits limits;
  limits.worker_cpu_s = 2.0;
  limits.worker_wall_s = 3.0;
  for (const fs::path& p : kept_inputs("pdf")) {
    SCOPED_TRACE(p.filename().string());
    const std::vector<std::uint8_t> bytes = read_bytes(p);
    const std::string name = "stick/" + p.filename().string();
    const auto t0 = std::chrono::steady_clock::now();
    try {
      const PdfInfo info = probe_pdf(bytes, name, limits);
      ASSERT_GE(info.pages, 1);
      const PdfPage page = render_pdf_page(bytes, name, 1, limits);
      EXPECT_FALSE(page.grey.empty());
    } catch (const PdfError& e) {
      const std::string what = e.what();
      EXPECT_TRUE(is_one_line(what)) << what;
      EXPECT_EQ(what.rfind("pdf '" + name + "': ", 0), 0u) << what;
      EXPECT_TRUE(e.kind() == PdfError::Kind::Damaged || e.kind() == PdfError::Kind::TooLarge ||
                  e.kind() == PdfError::Kind::Timeout || e.kind() == PdfError::Kind::WorkerCrashed)
          << what;
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(s, 2 * limits.worker_wall_s + 2.0);  // a probe and a render, each killed at worker_wall_s
  }
}

}  // namespace
}  // namespace hk::vision
