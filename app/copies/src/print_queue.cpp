// A copy sent to a CUPS queue (print_queue.hpp).
#include "copies/print_queue.hpp"

#include <cups/cups.h>

#include <memory>

#include "hk/text.hpp"

namespace hk::app {
namespace {

/// IPP's printer-state: 3 idle, 4 processing, 5 stopped.
constexpr const char* kStopped = "5";

std::string cups_error() {
  const char* e = cupsLastErrorString();
  return e && *e ? std::string(e) : std::string("no reason given");
}

}  // namespace

PrintOutcome print_pdf(const std::string& queue, const std::string& pdf_path, const std::string& title) {
  PrintOutcome out;
  const std::string name = "printer " + hk::quoted(queue);
  if (queue.empty()) {
    out.error = "no printer is set ([copy] printer)";
    return out;
  }
  std::unique_ptr<cups_dest_t, void (*)(cups_dest_t*)> dest(cupsGetNamedDest(CUPS_HTTP_DEFAULT, queue.c_str(), nullptr),
                                                            [](cups_dest_t* d) { cupsFreeDests(1, d); });
  if (!dest) {
    out.error = name + " cannot be found (" + cups_error() + ")";
    return out;
  }
  const char* state = cupsGetOption("printer-state", dest->num_options, dest->options);
  if (state && std::string(state) == kStopped) {
    const char* why = cupsGetOption("printer-state-message", dest->num_options, dest->options);
    out.error = name + " is stopped" + (why && *why ? " (" + one_line(why, 120) + ")" : std::string());
    return out;
  }
  const char* accepting = cupsGetOption("printer-is-accepting-jobs", dest->num_options, dest->options);
  if (accepting && std::string(accepting) == "false") {
    out.error = name + " does not accept jobs";
    return out;
  }
  out.job_id = cupsPrintFile2(CUPS_HTTP_DEFAULT, queue.c_str(), pdf_path.c_str(), title.c_str(), 0, nullptr);
  if (out.job_id <= 0) {
    out.job_id = 0;
    out.error = name + " refused the copy (" + cups_error() + ")";
  }
  return out;
}

}  // namespace hk::app
