// The cone tests of the topological VPLs (techniques/topovpl/gate_cones.h, notes 004 E7, E8):
// the light-assignment test must be conservative with respect to the exact per-pixel test.
#include <random>

#include <gtest/gtest.h>

#include "techniques/topovpl/gate_cones.h"

using gilab::topo::coneHitsSphere;
using gilab::topo::GateDisk;
using gilab::topo::throughGate;

TEST(CpuTopoCones, ExactTestCrossesTheDiskOnly) {
    const GateDisk g{{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, 0.5f};
    const glm::vec3 x(-1.0f, 0.0f, 0.0f);
    EXPECT_TRUE(throughGate(x, {1.0f, 0.0f, 0.0f}, g));
    EXPECT_TRUE(throughGate(x, {1.0f, 0.9f, 0.0f}, g));    // crosses at y = 0.45
    EXPECT_FALSE(throughGate(x, {1.0f, 1.1f, 0.0f}, g));   // crosses at y = 0.55
    EXPECT_FALSE(throughGate(x, {-0.5f, 0.0f, 0.0f}, g));  // stops before the plane
    EXPECT_FALSE(throughGate(x, {-1.0f, 1.0f, 0.0f}, g));  // parallel to the plane
    EXPECT_FALSE(throughGate(x, x, g));                    // degenerate segment, no NaN
    EXPECT_TRUE(throughGate({1.0f, 0.0f, 0.0f}, {-1.0f, 0.2f, 0.0f}, g));  // either way
}

TEST(CpuTopoCones, SphereTestRejectsTheNearSideAndFarAngles) {
    const GateDisk g{{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, 0.5f};
    const glm::vec3 x(-1.0f, 0.0f, 0.0f);
    EXPECT_TRUE(coneHitsSphere(x, g, {2.0f, 0.0f, 0.0f}, 0.1f));
    EXPECT_FALSE(coneHitsSphere(x, g, {-3.0f, 0.0f, 0.0f}, 0.5f));  // behind the VPL's side
    EXPECT_FALSE(coneHitsSphere(x, g, {2.0f, 5.0f, 0.0f}, 0.5f));   // far off the cone
    EXPECT_TRUE(coneHitsSphere(x, g, {2.0f, 5.0f, 0.0f}, 5.0f));    // a big sphere reaches it
    // A VPL inside the gate's sphere: everything past the plane.
    EXPECT_TRUE(coneHitsSphere({-0.1f, 0.0f, 0.0f}, g, {1.0f, 3.0f, 0.0f}, 0.1f));
}

// Random VPLs, gates and spheres: whenever a point inside the sphere passes the exact test,
// the sphere test passes too (the assignment never drops a light the pixel would see).
TEST(CpuTopoCones, SphereTestIsConservative) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    auto vec = [&] { return glm::vec3(u(rng), u(rng), u(rng)); };
    int accepted = 0, rejected = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        GateDisk g;
        g.centre = vec();
        glm::vec3 n = vec();
        if (glm::length(n) < 0.1f) continue;
        g.normal = glm::normalize(n);
        g.radius = 0.05f + 0.5f * (u(rng) + 1.0f) * 0.5f;
        const glm::vec3 x = 3.0f * vec();
        const glm::vec3 s = 3.0f * vec();
        const float rho = 0.05f + 0.6f * (u(rng) + 1.0f) * 0.5f;
        const bool sphere = coneHitsSphere(x, g, s, rho);
        for (int k = 0; k < 16; ++k) {
            glm::vec3 d = vec();
            if (glm::length(d) > 1.0f) continue;
            const glm::vec3 p = s + rho * d;
            if (throughGate(x, p, g)) {
                ++accepted;
                ASSERT_TRUE(sphere) << "trial " << trial;
            }
        }
        if (!sphere) ++rejected;
    }
    EXPECT_GT(accepted, 1000);  // the check ran on real cases
    EXPECT_GT(rejected, 1000);  // and the test culls
}
