#pragma once
/// @file test_paths.hpp
/// Where the tests and benchmarks find their files: the test data, the shipped pictures and the programs
/// this build makes. The absolute paths are compiled into test_paths.cpp alone, so every other test source
/// compiles the same wherever the tree is checked out (a compiler cache hits across clones).

namespace hk::test {

extern const char* const kTestDataDir;         ///< tests/data of this tree
extern const char* const kShippedPicturesDir;  ///< data/pictures of this tree
extern const char* const kKioskExe;            ///< the haptic-kiosk executable of this build
extern const char* const kStickHelperExe;      ///< the hk-stick-mount executable of this build

}  // namespace hk::test

#define HK_TEST_DATA_DIR (::hk::test::kTestDataDir)
#define HK_SHIPPED_PICTURES_DIR (::hk::test::kShippedPicturesDir)
#define HK_KIOSK_EXE (::hk::test::kKioskExe)
#define HK_STICK_HELPER_EXE (::hk::test::kStickHelperExe)
