#pragma once
/// @file scans.hpp
/// Scans of pages as a scanner or a phone makes them, made in the test from a PDF (pdftoppm), and the
/// measure OCR is judged by: the share of the page's words (pdftotext of the same page) that were read.

#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace hk::test {

inline int shell(const std::string& cmd) {
  const int raw = std::system(cmd.c_str());
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
}

/// Whether pdftoppm and pdftotext (poppler-utils) are there.
inline bool have_poppler_utils() {
  return shell("command -v pdftoppm >/dev/null 2>&1 && command -v pdftotext >/dev/null 2>&1") == 0;
}

/// The words of `text`: lower case, letters and digits only, empty ones left out.
inline std::vector<std::string> words_of(const std::string& text) {
  std::vector<std::string> out;
  std::string w;
  for (char c : text + " ") {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      w += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!w.empty()) {
      out.push_back(w);
      w.clear();
    }
  }
  return out;
}

/// Share of the words of `truth` that `read` has too (each read word counts once: a multiset intersection).
inline double word_recall(const std::vector<std::string>& truth, const std::vector<std::string>& read) {
  std::map<std::string, int> have;
  for (const std::string& w : read) ++have[w];
  int found = 0;
  for (const std::string& w : truth)
    if (have[w] > 0) {
      --have[w];
      ++found;
    }
  return truth.empty() ? 0.0 : static_cast<double>(found) / static_cast<double>(truth.size());
}

/// A scan of `page` of `pdf` as a scanner or a phone gives it: drawn at `dpi`, turned by `degrees`, with
/// Gaussian sensor noise (sigma 6 grey levels, the same for the same page and dpi), as JPEG bytes at quality
/// 80 (grey).
inline std::vector<std::uint8_t> scan_jpeg(const std::filesystem::path& pdf, int page, int dpi, double degrees,
                                           const std::filesystem::path& dir) {
  const std::filesystem::path stem = dir / ("p" + std::to_string(page) + "_" + std::to_string(dpi));
  if (shell("pdftoppm -gray -r " + std::to_string(dpi) + " -f " + std::to_string(page) + " -l " + std::to_string(page) +
            " -singlefile -png '" + pdf.string() + "' '" + stem.string() + "'") != 0)
    return {};
  cv::Mat grey = cv::imread(stem.string() + ".png", cv::IMREAD_GRAYSCALE);
  if (grey.empty()) return {};
  const cv::Mat turn = cv::getRotationMatrix2D(cv::Point2f(grey.cols / 2.0f, grey.rows / 2.0f), degrees, 1.0);
  cv::warpAffine(grey, grey, turn, grey.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(255));
  cv::Mat noise(grey.size(), CV_16SC1), noisy;
  cv::RNG rng(static_cast<std::uint64_t>(page) * 1000 + static_cast<std::uint64_t>(dpi));  // the same scan every run
  rng.fill(noise, cv::RNG::NORMAL, 0, 6);
  grey.convertTo(noisy, CV_16SC1);
  noisy += noise;
  noisy.convertTo(grey, CV_8UC1);
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", grey, jpeg, {cv::IMWRITE_JPEG_QUALITY, 80});
  return jpeg;
}

/// `page` of `pdf` as pdftoppm draws it at `dpi`, grey (CV_8UC1), clean (not turned, no noise); empty when pdftoppm
/// fails. The PNG is left in `dir`.
inline cv::Mat draw_page(const std::filesystem::path& pdf, int page, int dpi, const std::filesystem::path& dir) {
  const std::filesystem::path stem = dir / ("page" + std::to_string(page) + "_" + std::to_string(dpi));
  if (shell("pdftoppm -gray -r " + std::to_string(dpi) + " -f " + std::to_string(page) + " -l " + std::to_string(page) +
            " -singlefile -png '" + pdf.string() + "' '" + stem.string() + "'") != 0)
    return {};
  return cv::imread(stem.string() + ".png", cv::IMREAD_GRAYSCALE);
}

/// The text layer of `page` of `pdf`, as pdftotext gives it.
inline std::string pdftotext_page(const std::filesystem::path& pdf, int page, const std::filesystem::path& dir) {
  const std::filesystem::path out = dir / "truth.txt";
  if (shell("pdftotext -f " + std::to_string(page) + " -l " + std::to_string(page) + " '" + pdf.string() + "' '" +
            out.string() + "'") != 0)
    return {};
  std::ifstream f(out);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace hk::test
