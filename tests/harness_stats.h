#pragma once
// A technique's named number (TechniqueContext::stat) from a harness, for the technique tests.
#include <string>

#include <gtest/gtest.h>

#include "core/technique/frame_harness.h"

namespace gilab::test {

/** The last value of stat `name`; a test failure (and -1) when the technique never set it. */
inline double stat(const FrameHarness& h, const std::string& name) {
    for (const auto& [n, v] : h.stats())
        if (n == name) return v;
    ADD_FAILURE() << "no stat " << name;
    return -1.0;
}

}  // namespace gilab::test
