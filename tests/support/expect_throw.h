#pragma once
/// \file expect_throw.h
/// Checks on the one-line errors the project throws (core/errors.h): what a call throws, and
/// that its message is one line.

#include <exception>
#include <string>

#include <gtest/gtest.h>

#include "core/errors.h"

namespace lobe::test {

/// The message of the InvalidInput `fn` throws (empty when it throws nothing); any other
/// exception passes through.
template <typename Fn> std::string invalid_input_message(Fn&& fn)
{
    try {
        fn();
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "";
}

/// Calls `f`, expects an exception of type E with a non-empty one-line message, and returns
/// the message (empty, and the test failed, when `f` throws nothing or another type).
template <class E, class F> std::string expect_one_line_throw(F&& f)
{
    try {
        f();
    } catch (const E& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        EXPECT_FALSE(what.empty());
        return what;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "wrong exception type: " << e.what();
        return {};
    }
    ADD_FAILURE() << "no exception";
    return {};
}

} // namespace lobe::test
