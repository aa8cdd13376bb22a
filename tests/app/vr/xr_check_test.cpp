// Checked OpenXR calls (app/vr/xr_check.h): a failure names the call as written, its result
// and where it was made.
#include <gtest/gtest.h>

#include "app/vr/xr_check.h"

namespace lobe {
namespace {

XrResult session_lost() { return XR_ERROR_SESSION_LOST; }

TEST(XrCheck, AFailedCallThrowsNamingTheCallItsResultAndFileAndLine)
{
    EXPECT_NO_THROW(LOBE_XR_CHECK(XR_SUCCESS));
    EXPECT_NO_THROW(LOBE_XR_CHECK(XR_SESSION_LOSS_PENDING)); // a success code
    const int line = __LINE__ + 2;
    try {
        LOBE_XR_CHECK(session_lost());
        FAIL() << "a failed call did not throw";
    } catch (const XrFailure& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("session_lost()"), std::string::npos) << m;
        EXPECT_NE(m.find("XR_ERROR_SESSION_LOST"), std::string::npos) << m;
        EXPECT_NE(m.find("tests/app/vr/xr_check_test.cpp:" + std::to_string(line)), std::string::npos) << m;
        EXPECT_EQ(m.find("../"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

} // namespace
} // namespace lobe
