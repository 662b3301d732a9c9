// Test support: expecting an exception of a given type whose message names things.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

namespace envmis::test {

// Expects `action` to throw an Error whose message contains each of `parts`.
template <class Error, class Action>
void expect_error(Action&& action, std::initializer_list<std::string> parts) {
    try {
        action();
        ADD_FAILURE() << "nothing thrown";
    } catch (const Error& e) {
        for (const std::string& part : parts)
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << "'" << part << "' not in: " << e.what();
    }
}

}  // namespace envmis::test
