// hk-stick-mount: the installed kiosk's mount helper for USB sticks (see stick_helper.hpp).
#include <cstdio>

#include "stick_helper.hpp"

int main(int argc, char** argv) { return hk::stick_helper::helper_main(argc, argv, stdout, stderr); }
