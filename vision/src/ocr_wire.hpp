#pragma once
/// @file ocr_wire.hpp
/// The request the kiosk sends hk-ocr-worker in its arguments, written and read in one place (vision/ocr.hpp
/// for the contract; the pixels come on worker::kInputFd, width x height bytes, row after row). Private to
/// vision.

#include <cstddef>
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

/// What a record of the answer holds. The answer is u32 kOcrMagic, then records as the worker works, each u8
/// OcrRecord, u32 size [bytes], then that many bytes:
///   block:   u32 lines, u32 words; per word: str text, f64 x, y, w, h [px], f64 confidence [0, 1]; then str
///            the Tesseract language most of its words were read in ("fra"; "" when none says)
///   end:     u32 words seen (the last record of an answer that worked)
///   refusal: u8 OcrError::Kind, str problem (the last record of one that did not)
enum class OcrRecord : std::uint8_t { end = 0, refusal = 1, block = 2 };

/// One record: its tag, the size of `payload` and the payload.
inline std::string ocr_record(OcrRecord tag, const worker::WireWriter& payload) {
  worker::WireWriter out;
  out.u8(static_cast<std::uint8_t>(tag));
  out.u32(static_cast<std::uint32_t>(payload.bytes().size()));
  out.raw(payload.bytes().data(), payload.bytes().size());
  return out.bytes();
}

/// The kiosk's side of the answer, read record by record as it comes down the pipe, every size and value
/// checked (the worker reads a stranger's pixels, so its answer is not trusted either).
class OcrAnswerReader {
 public:
  explicit OcrAnswerReader(const OcrParams& params) : p_(params) {}
  /// Reads the records of `answer` (every byte so far: each call a longer prefix of the same answer) not read
  /// yet; calls OcrParams::on_block with each block. False once the answer is malformed (nothing more is read).
  bool feed(const std::string& answer);
  bool ended() const { return ended_; }      ///< the end record was read
  bool refused() const { return refused_; }  ///< a refusal record was read: refusal_kind and refusal_problem say it
  OcrError::Kind refusal_kind() const { return refusal_kind_; }
  const std::string& refusal_problem() const { return refusal_problem_; }
  /// What was read so far (OcrResult::ms and the worker's memory are the caller's to set).
  OcrResult& result() { return out_; }

 private:
  bool read_record(OcrRecord tag, const std::string& payload);
  const OcrParams& p_;
  std::size_t at_ = 0;  // bytes of the answer read
  bool bad_ = false, ended_ = false, refused_ = false;
  OcrError::Kind refusal_kind_ = OcrError::Kind::WorkerCrashed;
  std::string refusal_problem_;
  double confidence_sum_ = 0;
  OcrResult out_;
};

/// The kiosk's side of the whole answer of `run` (OcrAnswerReader over it).
/// @throws OcrError: the worker's own refusal, or what went wrong with the run (cancelled, timed out, crashed,
///         or an answer that does not parse: "the text reader gave no usable answer").
OcrResult read_ocr_answer(const worker::WorkerRun& run, const std::string& name, const OcrParams& params);

}  // namespace hk::vision
