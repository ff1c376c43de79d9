// One way to fail: every module's error derives from hk::Error, so a caller that only
// reports catches one type; and a bad input through the CLI ends in exactly one line naming it.
#include <gtest/gtest.h>

#include <type_traits>

#include "audio/messages.hpp"
#include "audio/speech.hpp"
#include "audio/wav.hpp"
#include "cli/explore.hpp"
#include "config/load.hpp"
#include "formats/app_error.hpp"
#include "formats/picture_notes.hpp"
#include "haptics/device.hpp"
#include "haptics/hand_path.hpp"
#include "haptics/multires.hpp"
#include "hk/error.hpp"
#include "runtime/device_setup.hpp"
#include "sticks/usb_stick.hpp"
#include "test_paths.hpp"
#include "vision/frame_source.hpp"
#include "vision/intake.hpp"
#include "vision/pdf.hpp"
#include "vision/stick_scan.hpp"

namespace hk {
namespace {

template <class... E>
constexpr bool all_hk_errors = (std::is_base_of_v<Error, E> && ...);

static_assert(all_hk_errors<CurveError, DeviceError, HandFileError>);
static_assert(all_hk_errors<vision::InputError, vision::PdfError, vision::CameraError, vision::StickError,
                            sticks::StickMountError>);
static_assert(all_hk_errors<config::ConfigError>);
static_assert(all_hk_errors<audio::SpeechError, audio::MessageError, audio::WavError>);
static_assert(all_hk_errors<app::ExploreError, app::DeviceChoiceError, app::PictureNotesError, app::AppError>);

TEST(Errors, ABadPictureIsCaughtAsAnHkErrorWithOneLine) {
  try {
    (void)vision::load_image(std::string(HK_TEST_DATA_DIR) + "/bad/huge_declared.png", {});
    FAIL() << "a 10^10-pixel header was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find("huge_declared.png"), std::string::npos) << what;
    EXPECT_NE(what.find("limit"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace hk
