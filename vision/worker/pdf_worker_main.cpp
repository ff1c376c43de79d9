// hk-pdf-worker: the process that runs poppler on one PDF page for the kiosk (vision/pdf.hpp). Started by
// vision::render_pdf_page / probe_pdf with posix_spawn, never by hand: the document comes on descriptor 3,
// the answer goes to descriptor 4, the request is in the arguments.
#include "vision/pdf.hpp"

int main(int argc, char** argv) { return hk::vision::pdf_worker_entry(argc, argv); }
