#pragma once
/**
 * The fixture of every Gpu* test: a Vulkan context with the validation layers on, and a teardown
 * that fails the test on any validation error or warning (printing the messages).
 */
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "core/vk/context.h"

namespace gilab::test {

class ValidatedGpuTest : public ::testing::Test {
protected:
    void SetUp() override {
        vk::ContextOptions options;
        options.validation = true;
        m_ctx = std::make_unique<vk::Context>(options);
    }
    void TearDown() override {
        for (const std::string& m : m_ctx->validationMessages())
            ADD_FAILURE() << m;
        EXPECT_EQ(m_ctx->validationErrorCount(), 0u);
        EXPECT_EQ(m_ctx->validationWarningCount(), 0u);
        m_ctx.reset();
    }
    std::unique_ptr<vk::Context> m_ctx;
};

}  // namespace gilab::test
