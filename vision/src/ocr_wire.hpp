#pragma once
/// @file ocr_wire.hpp
/// The request the kiosk sends hk-ocr-worker in its arguments, written and read in one place (vision/ocr.hpp
/// for the contract; the pixels come on worker::kInputFd, width x height bytes, row after row). Private to
/// vision.

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "vision/ocr.hpp"
#include "worker_process.hpp"

namespace hk::vision {

inline constexpr std::uint32_t kOcrMagic = 0x434F4B48;  // "HKOC"

/// What the worker is asked.
struct OcrRequest {
  int width = 0, height = 0;  ///< of the grey picture [px]
  OcrParams params;
};

/// argv[1..] of the worker for a `width` x `height` picture.
inline std::vector<std::string> ocr_request_args(int width, int height, const OcrParams& p) {
  return {std::to_string(width),
          std::to_string(height),
          p.languages,
          p.tessdata_dir.empty() ? "-" : p.tessdata_dir,
          worker::arg(p.min_word_confidence),
          worker::arg(p.min_letter_share),
          worker::arg(p.worker_cpu_s),
          worker::arg(p.worker_max_memory_mb),
          std::to_string(static_cast<int>(p.fault))};
}

/// Reads what ocr_request_args wrote; false for anything else.
inline bool parse_ocr_request(int argc, char** argv, OcrRequest& rq) {
  if (argc != 10) return false;
  rq.width = std::atoi(argv[1]);
  rq.height = std::atoi(argv[2]);
  rq.params.languages = argv[3];
  rq.params.tessdata_dir = std::string(argv[4]) == "-" ? "" : argv[4];
  rq.params.min_word_confidence = std::strtod(argv[5], nullptr);
  rq.params.min_letter_share = std::strtod(argv[6], nullptr);
  rq.params.worker_cpu_s = std::strtod(argv[7], nullptr);
  rq.params.worker_max_memory_mb = std::strtod(argv[8], nullptr);
  const int fault = std::atoi(argv[9]);
  if (fault < 0 || fault > static_cast<int>(OcrFault::Memory)) return false;
  rq.params.fault = static_cast<OcrFault>(fault);
  return rq.width > 0 && rq.height > 0 && !rq.params.languages.empty();
}

/// The kiosk's side of the answer: what the worker of `run` sent, read with every size and value checked
/// (the worker reads a stranger's pixels, so its answer is not trusted either).
/// @throws OcrError: the worker's own refusal, or what went wrong with the run (cancelled, timed out, crashed,
///         or an answer that does not parse: "the text reader gave no usable answer").
OcrResult read_ocr_answer(const worker::WorkerRun& run, const std::string& name, const OcrParams& params);

}  // namespace hk::vision
