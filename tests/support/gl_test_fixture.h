#pragma once
// Gives GL tests a headless (EGL surfaceless) context shared by the tests of one suite.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "renderer/gl/context.h"

namespace lucent::test {

class HeadlessGlTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        if (context_) return;
        try {
            context_ = gl::create_headless_context();
        } catch (const gl::ContextError& e) {
            error_ = e.what();
        }
    }
    static void TearDownTestSuite() { context_.reset(); }
    void SetUp() override {
        ASSERT_NE(context_, nullptr) << "no headless GL context: " << error_;
        context_->make_current();
    }
    static gl::Context& context() { return *context_; }

private:
    static inline std::unique_ptr<gl::Context> context_;
    static inline std::string error_;
};

}  // namespace lucent::test
