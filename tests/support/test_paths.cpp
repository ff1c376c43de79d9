// Where the tests and benchmarks find their files (test_paths.hpp); the paths come from the build.
#include "test_paths.hpp"

namespace hk::test {

const char* const kTestDataDir = HK_TEST_DATA_DIR_PATH;
const char* const kShippedPicturesDir = HK_SHIPPED_PICTURES_DIR_PATH;
const char* const kKioskExe = HK_KIOSK_EXE_PATH;
const char* const kStickHelperExe = HK_STICK_HELPER_EXE_PATH;

}  // namespace hk::test
