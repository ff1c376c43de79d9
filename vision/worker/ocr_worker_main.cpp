// hk-ocr-worker: the process that runs Tesseract on one picture for the kiosk (vision/ocr.hpp). Started by
// vision::recognise_text with posix_spawn, never by hand: the pixels come on descriptor 3, the answer goes to
// descriptor 4, the request is in the arguments.
#include "vision/ocr.hpp"

int main(int argc, char** argv) { return hk::vision::ocr_worker_entry(argc, argv); }
