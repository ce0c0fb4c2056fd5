#pragma once
// Tests that need an X display. Run by hand without one they skip; where a display is
// promised (scripts/test, and so CI, sets LUCENT_REQUIRE_DISPLAY=1 and runs ctest under
// xvfb-run when DISPLAY is unset), a missing display fails the test instead of letting
// the window and end-to-end suites pass by skipping.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace lucent::test {

inline bool display_required() {
    const char* required = std::getenv("LUCENT_REQUIRE_DISPLAY");
    return required && *required && std::string(required) != "0";
}

}  // namespace lucent::test

#define LUCENT_REQUIRE_DISPLAY()                                                        \
    do {                                                                                \
        if (!std::getenv("DISPLAY")) {                                                  \
            if (::lucent::test::display_required())                                     \
                FAIL()                                                                  \
                    << "no X display, but LUCENT_REQUIRE_DISPLAY is set (scripts/test " \
                       "runs ctest under xvfb-run: is xvfb installed?)";                \
            GTEST_SKIP() << "no X display (scripts/test runs ctest under xvfb-run)";    \
        }                                                                               \
    } while (0)
