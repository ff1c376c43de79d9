#pragma once
/// @file print_queue.hpp
/// A copy sent to a printer through CUPS (libcups): the queue staff named, checked before the job is sent (it
/// exists, it is not stopped, it accepts jobs), so that the visitor hears at once when the copy will not come.
/// The CUPS server is libcups' default (the local cupsd, or the CUPS_SERVER environment variable). Blocking (a
/// network round trip): call it off the window thread.

#include <string>

namespace hk::app {

/// What became of a print request.
struct PrintOutcome {
  int job_id = 0;     ///< the CUPS job, > 0 when it was queued
  std::string error;  ///< one line when it was not ("printer 'front-desk' is stopped"); empty when queued
  bool queued() const { return job_id > 0; }
};

/// Sends the PDF file `pdf_path` to the CUPS queue `queue` as a job titled `title`. Never throws but
/// std::bad_alloc: a queue that does not exist, is stopped or refuses jobs, or a server that cannot be reached,
/// gives `error` (one line naming the queue) and no job.
PrintOutcome print_pdf(const std::string& queue, const std::string& pdf_path, const std::string& title);

}  // namespace hk::app
