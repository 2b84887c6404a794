// ssvp (screen-space VPL propagation, Aranha et al.; techniques/ssvp/README.md): K-means on the
// GPU, the technique's energy against the path tracer's bounces, parameters and light support.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/gpu_test_fixture.h"
#include "tests/harness_stats.h"
#include "tests/indirect_energy.h"

#include "core/gpu/gpu_scene.h"
#include "core/image/image.h"
#include "core/image/image_io.h"
#include "core/scene/animation.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/vk/buffer.h"
#include "core/vk/context.h"
#include "core/vpl/paraboloid_maps.h"
#include "core/vpl/vpl.h"
#include "experiments/runner/same_vpl.h"
#include "reference/path_tracer.h"
#include "techniques/ssvp/ssvp_propagation.h"
#include "techniques/ssvp/ssvp_settings.h"

namespace gilab {
namespace {

using GpuSsvp = test::ValidatedGpuTest;

Scene cornell(const std::string& variant, int size) {
    Scene scene =
        loadSceneFile(std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json", variant);
    scene.settings.width = size;
    scene.settings.height = size;
    return scene;
}

ParamSet ssvpParams(const std::map<std::string, std::string>& values) {
    ParamSet p = TechniqueRegistry::instance().defaultParams("ssvp");
    for (const auto& [k, v] : values)
        p.set(k, v);
    return p;
}

using test::stat;

/** Sum of one path-tracer layer (maxBounces bounces, spp samples). */
double referenceLayerSum(const Scene& scene, int maxBounces, ref::Layer layer, uint32_t spp) {
    ref::ReferenceSettings settings;
    settings.maxBounces = maxBounces;
    settings.seed = 11;
    ref::PathTracer tracer(scene, settings);
    ref::Accumulator acc;
    acc.reset(scene.settings.width, scene.settings.height);
    EXPECT_TRUE(tracer.addSamples(acc, spp));
    const Image image = ref::meanImage(acc, layer);
    double sum = 0.0;
    for (float v : image.values())
        sum += v;
    return sum;
}

double indirectSum(FrameHarness& h) {
    const std::vector<ImageLayer> layers = h.readLayers();
    return test::indirectLayerSum(layers);
}

// ---------------------------------------------------------------------------------------------
// K-means (SsvpPropagation on synthetic VPLs)
// ---------------------------------------------------------------------------------------------

struct KmeansResult {
    std::vector<GpuVplCluster> clusters;
    std::vector<GpuVpl> vpls;
    SsvpKmeansState state;
};

/** Clusters `vpls` once (`frames` frames, warm-started) with the given settings. */
KmeansResult runKmeans(vk::Context& ctx, const std::vector<GpuVpl>& vpls, SsvpSettings s,
                       int frames = 1) {
    Scene scene = makeCornellBox(CornellBoxParams{});
    scene.computeCaps();
    vk::GpuScene gpuScene(ctx, scene);
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                     VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                     VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    vk::Buffer vplBuffer(ctx, vpls.size() * sizeof(GpuVpl), usage, vk::MemoryUsage::DeviceLocal,
                         "test/vpls");
    vplBuffer.upload(vpls.data(), vpls.size() * sizeof(GpuVpl));
    vk::Buffer clusters(ctx, s.clusters * sizeof(GpuVplCluster), usage,
                        vk::MemoryUsage::DeviceLocal, "test/clusters");
    ctx.submitAndWait(
        [&](VkCommandBuffer cmd) { vkCmdFillBuffer(cmd, clusters.handle(), 0, VK_WHOLE_SIZE, 0); });
    ParaboloidSettings ps;
    ps.resolution = 16;
    ps.layers = s.clusters;
    ParaboloidMaps maps(ctx, gpuScene, clusters, ps, "test");
    SsvpPropagation propagation(ctx, vplBuffer, clusters, maps, "test");
    s.firstBounceVpls = uint32_t(vpls.size());
    propagation.setSettings(s, 1.0f);
    for (int f = 0; f < frames; ++f)
        ctx.submitAndWait(
            [&](VkCommandBuffer cmd) { propagation.recordClustering(cmd, SsvpRange::First); });
    KmeansResult r;
    r.clusters = clusters.downloadVector<GpuVplCluster>(s.clusters);
    r.vpls = vplBuffer.downloadVector<GpuVpl>(vpls.size());
    r.state = propagation.readState(SsvpRange::First);
    return r;
}

GpuVpl syntheticVpl(glm::vec3 p, glm::vec3 n, bool valid = true) {
    GpuVpl v;
    v.position = glm::vec4(p, valid ? 1.0f : 0.0f);
    v.normal = glm::vec4(glm::normalize(n), -1.0f);
    v.flux = glm::vec4(valid ? glm::vec3(1.0f) : glm::vec3(0.0f), 1.0f);
    return v;
}

/** VPLs on three walls of a unit corner (floor, back, left), a fifth of them invalid. */
std::vector<GpuVpl> cornerVpls(uint32_t n) {
    std::vector<GpuVpl> v;
    for (uint32_t k = 0; k < n; ++k) {
        const float a = float((k * 37) % 101) / 101.0f, b = float((k * 61) % 97) / 97.0f;
        switch (k % 3) {
            case 0:
                v.push_back(syntheticVpl({a, 0.0f, b}, {0, 1, 0}, k % 5 != 0));
                break;
            case 1:
                v.push_back(syntheticVpl({a, b, 0.0f}, {0, 0, 1}, k % 5 != 0));
                break;
            default:
                v.push_back(syntheticVpl({0.0f, a, b}, {1, 0, 0}, k % 5 != 0));
                break;
        }
    }
    return v;
}

/** The invariants every K-means result keeps: no NaN, no (0,0,0) or empty active cluster,
 *  every valid VPL in an active cluster whose centroid is its members' mean. */
void expectSoundClusters(const KmeansResult& r, uint32_t clusterCount) {
    uint32_t members = 0, valid = 0;
    for (const GpuVpl& v : r.vpls) {
        if (v.position.w < 0.5f) continue;
        ++valid;
        const int c = int(v.normal.w);
        ASSERT_GE(c, 0);
        ASSERT_LT(c, int(clusterCount));
        EXPECT_GT(r.clusters[size_t(c)].position.w, 0.5f) << "VPL in an inactive cluster";
    }
    for (uint32_t j = 0; j < clusterCount; ++j) {
        const GpuVplCluster& c = r.clusters[j];
        for (int k = 0; k < 4; ++k) {
            ASSERT_TRUE(std::isfinite(c.position[k])) << "cluster " << j;
            ASSERT_TRUE(std::isfinite(c.normal[k])) << "cluster " << j;
            ASSERT_TRUE(std::isfinite(c.mean[k])) << "cluster " << j;
        }
        if (c.position.w < 0.5f) {
            EXPECT_EQ(c.normal.w, 0.0f) << "an inactive cluster has no members";
            continue;
        }
        EXPECT_GT(c.normal.w, 0.0f) << "an active cluster is never empty";
        EXPECT_NEAR(glm::length(glm::vec3(c.normal)), 1.0f, 1e-4f);
        glm::vec3 sum(0.0f);
        uint32_t count = 0;
        for (const GpuVpl& v : r.vpls)
            if (v.position.w > 0.5f && int(v.normal.w) == int(j)) {
                sum += glm::vec3(v.position);
                ++count;
            }
        // After an update the centroid is the mean of the assignment it was computed from; the
        // final assignment equals it when K-means converged.
        if (r.state.converged) {
            EXPECT_EQ(float(count), c.normal.w);
            const glm::vec3 mean = sum / float(count);
            EXPECT_LT(glm::length(mean - glm::vec3(c.mean)), 1e-5f) << "cluster " << j;
        }
        members += uint32_t(c.normal.w);
    }
    if (r.state.converged) {
        EXPECT_EQ(members, valid);
    }
}

TEST_F(GpuSsvp, KmeansIsDeterministicAndNeverEmptyOrNaN) {
    SsvpSettings s;
    s.clusters = 8;
    s.kmeansIterations = 20;
    const std::vector<GpuVpl> vpls = cornerVpls(256);
    const KmeansResult a = runKmeans(*m_ctx, vpls, s);
    const KmeansResult b = runKmeans(*m_ctx, vpls, s);
    expectSoundClusters(a, s.clusters);
    EXPECT_TRUE(a.state.converged) << a.state.iterations << " iterations";
    EXPECT_EQ(a.state.active, s.clusters);
    ASSERT_EQ(a.clusters.size(), b.clusters.size());
    for (size_t j = 0; j < a.clusters.size(); ++j) {
        EXPECT_EQ(a.clusters[j].position, b.clusters[j].position) << j;
        EXPECT_EQ(a.clusters[j].normal, b.clusters[j].normal) << j;
    }
    for (size_t i = 0; i < vpls.size(); ++i)
        EXPECT_EQ(a.vpls[i].normal.w, b.vpls[i].normal.w) << i;
    // The corrected metric never mixes the three walls: each cluster's members share a normal.
    for (const GpuVpl& v : a.vpls) {
        if (v.position.w < 0.5f) continue;
        const GpuVplCluster& c = a.clusters[size_t(v.normal.w)];
        EXPECT_GT(glm::dot(glm::vec3(v.normal), glm::vec3(c.normal)), 0.99f);
    }
    // A different seed may give other clusters, still sound.
    s.kmeansSeed = 7;
    expectSoundClusters(runKmeans(*m_ctx, vpls, s), s.clusters);
}

// Degenerate input: more clusters than distinct VPLs, opposing normals at one point, a single
// valid VPL, no valid VPL. Empty clusters are re-seeded or stay inactive, never NaN.
TEST_F(GpuSsvp, KmeansSurvivesDegenerateVpls) {
    SsvpSettings s;
    s.clusters = 16;
    s.kmeansIterations = 5;
    std::vector<GpuVpl> fewPoints;
    for (int k = 0; k < 64; ++k)
        fewPoints.push_back(syntheticVpl({float(k % 3), 0.0f, 0.0f},
                                         k % 2 ? glm::vec3(0, 1, 0) : glm::vec3(0, -1, 0)));
    KmeansResult r = runKmeans(*m_ctx, fewPoints, s, 3);
    expectSoundClusters(r, s.clusters);
    EXPECT_LE(r.state.active, 6u);  // 3 points x 2 normals
    EXPECT_GE(r.state.active, 2u);

    std::vector<GpuVpl> one(32, syntheticVpl({0.5f, 0.5f, 0.5f}, {0, 1, 0}, false));
    one[5] = syntheticVpl({0.5f, 0.5f, 0.5f}, {0, 1, 0});
    r = runKmeans(*m_ctx, one, s, 2);
    expectSoundClusters(r, s.clusters);
    EXPECT_EQ(r.state.active, 1u);

    std::vector<GpuVpl> none(32, syntheticVpl({0.5f, 0.5f, 0.5f}, {0, 1, 0}, false));
    r = runKmeans(*m_ctx, none, s, 2);
    expectSoundClusters(r, s.clusters);
    EXPECT_EQ(r.state.active, 0u);
    EXPECT_EQ(r.state.assigned, 0u);
}

// Eq. 2 as printed (literal) rewards dissimilar normals: it groups VPLs of different walls and
// does not converge, where the corrected metric converges on one wall per cluster.
TEST_F(GpuSsvp, LiteralMetricMixesNormalsTheCorrectedOneDoesNot) {
    SsvpSettings s;
    s.clusters = 3;
    s.kmeansIterations = 20;
    s.positionWeight = 0.1f;
    s.normalWeight = 1.0f;
    const std::vector<GpuVpl> vpls = cornerVpls(192);
    auto mixed = [](const KmeansResult& r) {
        int n = 0;
        for (const GpuVpl& v : r.vpls)
            if (v.position.w > 0.5f &&
                glm::dot(glm::vec3(v.normal), glm::vec3(r.clusters[size_t(v.normal.w)].normal)) <
                    0.99f)
                ++n;
        return n;
    };
    EXPECT_EQ(mixed(runKmeans(*m_ctx, vpls, s)), 0);
    s.literalMetric = true;
    // VPLs flee the clusters that share their normal: K-means oscillates between wall-mixed and
    // wall-pure clusters and never converges; the paper's 5 passes end on a mixed state.
    EXPECT_FALSE(runKmeans(*m_ctx, vpls, s).state.converged);
    s.kmeansIterations = 5;
    EXPECT_GT(mixed(runKmeans(*m_ctx, vpls, s)), 20);
}

// ---------------------------------------------------------------------------------------------
// The technique
// ---------------------------------------------------------------------------------------------

// The energy check: with weights = physical, the first-bounce VPLs carry the path tracer's
// one-bounce energy and the second-bounce VPLs about its two-bounce energy (spot-lit box). The
// maps' eyes sit on member VPLs (map_eye = nearest_vpl) so that the check measures the
// weighting, not the centroid-inside-an-object failure the paper reports (README.md measures that
// separately).
TEST_F(GpuSsvp, SpotCornellBouncesCarryThePathTracersEnergy) {
    const Scene scene = cornell("spot", 48);
    const std::map<std::string, std::string> base = {{"map_eye", "nearest_vpl"},
                                                     {"clusters", "16"},
                                                     {"first_bounce_vpls", "512"},
                                                     {"second_bounce_vpls", "512"}};
    std::map<std::string, std::string> oneBounce = base;
    oneBounce["bounces"] = "1";
    FrameHarness one(*m_ctx, scene, "ssvp", ssvpParams(oneBounce), defaultSharedParams());
    one.setup();
    one.renderFrame();
    const double first = indirectSum(one);
    FrameHarness two(*m_ctx, scene, "ssvp", ssvpParams(base), defaultSharedParams());
    two.setup();
    two.renderFrame();
    const double both = indirectSum(two);
    const double ref1 = referenceLayerSum(scene, 2, ref::Layer::Bounce1, 128);
    const double ref2 = referenceLayerSum(scene, 2, ref::Layer::Bounce2, 128);
    ASSERT_GT(ref1, 0.0);
    ASSERT_GT(ref2, 0.0);
    std::printf("spot Cornell 48^2: bounce 1 ssvp / reference = %.3f, bounce 2 = %.3f\n",
                first / ref1, (both - first) / ref2);
    EXPECT_GT(first / ref1, 0.8);
    EXPECT_LT(first / ref1, 1.25);
    EXPECT_GT((both - first) / ref2, 0.6);
    EXPECT_LT((both - first) / ref2, 1.6);
    EXPECT_GT(stat(two, "active_clusters"), 8.0);
    EXPECT_GE(stat(two, "kmeans_iterations"), 1.0);
}

// weights = paper divides both bounces by N = N1 + N2 (Eq. 6) with a constant flux per VPL: the
// image's energy then depends on N2, which the physical weighting's does not (documented).
TEST_F(GpuSsvp, PaperWeightsMakeTheEnergyDependOnN2) {
    const Scene scene = cornell("spot", 32);
    auto firstBounce = [&](const std::string& weights) {
        FrameHarness h(*m_ctx, scene, "ssvp", ssvpParams({{"weights", weights}, {"bounces", "1"}}),
                       defaultSharedParams());
        h.setup();
        h.renderFrame();
        return indirectSum(h);
    };
    // bounces = 1: N2 is not used, N = N1, both weightings agree.
    EXPECT_NEAR(firstBounce("paper") / firstBounce("physical"), 1.0, 1e-4);
    auto both = [&](const std::string& weights, const std::string& n2) {
        FrameHarness h(*m_ctx, scene, "ssvp",
                       ssvpParams({{"weights", weights}, {"second_bounce_vpls", n2}}),
                       defaultSharedParams());
        h.setup();
        h.renderFrame();
        return indirectSum(h);
    };
    // Physical: N2 changes the second bounce's noise, not its mean much; paper: more
    // second-bounce VPLs dim the first bounce (N1 / (N1 + N2)).
    const double physical = both("physical", "256") / both("physical", "1024");
    const double paper = both("paper", "256") / both("paper", "1024");
    std::printf("indirect energy N2 = 256 / N2 = 1024: physical %.3f, paper %.3f\n", physical,
                paper);
    EXPECT_NEAR(physical, 1.0, 0.08);
    EXPECT_GT(std::abs(paper - 1.0), 0.12);
}

// The clamp: off, nothing is removed; on (the default), the removed share is a finite number
// in the run's stats. Every frame of a moving light renders without NaN and without an update.
TEST_F(GpuSsvp, ClampStatsAndMovingLight) {
    Scene scene = cornell("spot_orbit", 32);
    FrameHarness off(*m_ctx, scene, "ssvp", ssvpParams({{"clamp_distance", "0"}}),
                     defaultSharedParams());
    off.setup();
    off.renderFrame();
    EXPECT_EQ(stat(off, "clamped_energy_percent"), 0.0);
    EXPECT_EQ(stat(off, "clamped_irradiance_mean"), 0.0);

    FrameHarness on(*m_ctx, scene, "ssvp", ssvpParams({{"clamp_distance", "0.1"}}),
                    defaultSharedParams());
    on.setup();
    on.renderFrame();
    const double removed = stat(on, "clamped_energy_percent");
    EXPECT_GT(removed, 0.0);
    EXPECT_LT(removed, 100.0);

    const SceneAnimation& anim = scene.animation;
    ASSERT_GT(anim.frameCount, 1);
    for (int f = 1; f < std::min(anim.frameCount, 3); ++f) {
        on.setFrameState(frameState(scene, f));
        const FrameTiming t = on.renderFrame();
        EXPECT_TRUE(t.dynamic);
        EXPECT_EQ(t.update, UpdateKind::None);  // everything is redone every frame anyway
        for (const ImageLayer& l : on.readLayers()) {
            EXPECT_TRUE(countNonFinite(l.image).allFinite()) << l.name;
        }
    }
}

// A static frame must not depend on the warm-up (issue 29): the harness warms up until the
// warm-started K-means has converged, so one requested warm-up frame and seven give the same
// image. Cold (warm-up 0) is left as asked.
TEST_F(GpuSsvp, WarmUpRunsUntilKmeansConvergesThenTheImageIsFixed) {
    const Scene scene = cornell("spot", 32);
    const ParamSet params = ssvpParams({{"clusters", "16"}});
    auto warmed = [&](int frames, WarmupResult& w) {
        FrameHarness h(*m_ctx, scene, "ssvp", params, defaultSharedParams());
        h.setup();
        w = h.warmUp(frames);
        h.renderFrame();
        EXPECT_EQ(stat(h, "kmeans_converged"), 1.0);
        return indirectSum(h);
    };
    WarmupResult one, seven, cold;
    const double a = warmed(1, one), b = warmed(7, seven);
    EXPECT_TRUE(one.settled);
    EXPECT_TRUE(seven.settled);
    EXPECT_GE(one.run, 1);
    EXPECT_EQ(seven.run, 7);
    EXPECT_GT(a, 0.0);
    EXPECT_NEAR(a / b, 1.0, 1e-5);
    FrameHarness h(*m_ctx, scene, "ssvp", params, defaultSharedParams());
    h.setup();
    cold = h.warmUp(0);
    EXPECT_EQ(cold.run, 0);

    // A slow start (issue 43: the test above never showed the extension): two K-means passes per
    // frame over 32 clusters do not converge in the one requested frame (measured: 7 frames), so
    // the harness renders more, and stops once it has. (One pass per frame never settles on this
    // box within the 64-frame cap; the run then records warmup_settled = false.)
    FrameHarness slow(*m_ctx, scene, "ssvp",
                      ssvpParams({{"clusters", "32"}, {"kmeans_iterations", "2"}}),
                      defaultSharedParams());
    slow.setup();
    const WarmupResult w = slow.warmUp(1);
    std::printf("slow start: %d warm-up frames for 1 requested, settled %d\n", w.run,
                int(w.settled));
    EXPECT_GT(w.run, 1);
    EXPECT_TRUE(w.settled);
    EXPECT_LT(w.run, FrameHarness::kMaxWarmupFrames);
    slow.renderFrame();
    EXPECT_EQ(stat(slow, "kmeans_converged"), 1.0);
}

// Interleaved sub-images, bounce by bounce (issue 43): the second-bounce disk sets hold
// N2 / C = 32 VPLs, too few for `blocks` at I = 4, which then split them like `modulo` (one strip
// of each disk per sub-image). Small sets are now split by fold (power-of-two strides). At I = 2
// and 4, for the first and the second bounce apart (bounces = 2 minus bounces = 1; no blur, so
// the pattern itself is scored), the mean equals I = 1's within `meanTolerance` and the default
// split's relMSE against I = 1 is no worse than fold's (10 % margin).
void checkInterleavedBounces(vk::Context& ctx, const Scene& scene, double meanTolerance) {
    auto indirect = [&](const std::string& interleave, const std::string& subsets,
                        const std::string& bounces) {
        FrameHarness h(ctx, scene, "ssvp",
                       ssvpParams({{"interleave", interleave},
                                   {"interleave_subsets", subsets},
                                   {"bounces", bounces},
                                   {"blur_radius", "0"}}),
                       defaultSharedParams());
        h.setup();
        h.warmUp(1);
        h.renderFrame();
        for (const ImageLayer& l : h.readLayers())
            if (l.name == "indirect") return l.image;
        throw Error("no indirect layer");
    };
    auto bounce = [&](const std::string& i, const std::string& subsets, int b) {
        Image one = indirect(i, subsets, "1");
        if (b == 1) return one;
        Image two = indirect(i, subsets, "2");
        for (size_t k = 0; k < two.values().size(); ++k)
            two.values()[k] -= one.values()[k];
        return two;
    };
    auto mean = [](const Image& im) {
        double s = 0.0;
        for (float v : im.values())
            s += v;
        return s / double(im.values().size());
    };
    // relMSE per channel, its epsilon 1e-2 of the reference's squared mean (the images' own
    // scale: the second bounce is about a tenth of the first).
    auto relMse = [&](const Image& a, const Image& ref) {
        const double eps = 1e-2 * mean(ref) * mean(ref);
        double s = 0.0;
        for (size_t k = 0; k < a.values().size(); ++k) {
            const double d = double(a.values()[k]) - double(ref.values()[k]);
            s += d * d / (double(ref.values()[k]) * double(ref.values()[k]) + eps);
        }
        return s / double(a.values().size());
    };
    for (int b : {1, 2}) {
        const Image full = bounce("1", "blocks", b);
        const double m1 = mean(full);
        ASSERT_GT(m1, 0.0);
        for (const char* i : {"2", "4"}) {
            std::map<std::string, double> err;
            for (const char* subsets : {"blocks", "fold", "modulo"}) {
                const Image im = bounce(i, subsets, b);
                err[subsets] = relMse(im, full);
                std::printf("bounce %d, I = %s, %s: mean / I=1 %.4f, relMSE vs I=1 %.4f\n", b, i,
                            subsets, mean(im) / m1, err[subsets]);
                if (std::string(subsets) != "modulo")
                    EXPECT_NEAR(mean(im) / m1, 1.0, meanTolerance)
                        << b << " " << i << " " << subsets;
            }
            EXPECT_LE(err["blocks"], 1.1 * err["fold"]) << "bounce " << b << ", I = " << i;
        }
    }
}

// Measured (lavapipe, 64^2): means within 1.9 % of I = 1 for every split; relMSE blocks / fold /
// modulo: bounce 1 at I = 4 0.96 / 1.01 / 2.41; bounce 2 at I = 4 0.88 / 0.88 / 0.77 (on this
// box the second bounce's strips cost nothing; Sponza's below shows them).
TEST_F(GpuSsvp, InterleavedSubImagesKeepEachBouncesMeanOnTheSpotBox) {
    checkInterleavedBounces(*m_ctx, cornell("spot", 64), 0.05);
}

// Sponza's sun (96^2; needs ../shared): relMSE at I = 4, bounce 2: blocks (= fold now) 0.54,
// modulo 0.68, which the old `blocks` was; bounce 1 blocks 1.30, fold 1.71, modulo 2.96. Means
// within 7 % for blocks and fold (the sub-images of 96^2 pixels see different receivers).
TEST_F(GpuSsvp, InterleavedSubImagesSpreadTheSecondBounceOnSponza) {
    const std::string file = std::string(GILAB_SOURCE_DIR) + "/scenes/sponza.json";
    Scene scene;
    try {
        scene = loadSceneFile(file, "");
    } catch (const Error& e) {
        GTEST_SKIP() << "shared scenes not found (" << e.what() << ")";
    }
    scene.settings.width = 96;
    scene.settings.height = 96;
    checkInterleavedBounces(*m_ctx, scene, 0.08);
}

// Does a cluster's map see its own members (issue 29)? On the spot-lit Cornell box at C = 8
// many members lie where their centroid's map does not see them (measured 65 % of the flux
// seen at 96^2); map_members = reassign moves them to a map that does, which returns the
// first bounce's energy (same-VPL exact 0.61 -> 1.00 at 96^2).
TEST_F(GpuSsvp, ReassignedMembersAreSeenByTheirMapAndKeepTheFirstBounce) {
    const Scene scene = cornell("spot", 48);
    auto run = [&](const std::string& members, double& seen, double& after, double& moved) {
        FrameHarness h(*m_ctx, scene, "ssvp",
                       ssvpParams({{"bounces", "1"}, {"map_members", members}}),
                       defaultSharedParams());
        h.setup();
        h.warmUp(1);
        h.renderFrame();
        seen = stat(h, "map_sees_member_flux_percent");
        after = stat(h, "shading_map_sees_member_flux_percent");
        moved = stat(h, "moved_member_flux_percent");
        return indirectSum(h);
    };
    double seenKeep, afterKeep, movedKeep, seen, after, moved;
    const double keep = run("keep", seenKeep, afterKeep, movedKeep);
    const double reassign = run("reassign", seen, after, moved);
    const double ref1 = referenceLayerSum(scene, 1, ref::Layer::Bounce1, 64);
    std::printf(
        "members seen %.1f %% (reassign: %.1f %%, moved %.1f %%); bounce 1 / R1: keep "
        "%.3f, reassign %.3f\n",
        seenKeep, after, moved, keep / ref1, reassign / ref1);
    EXPECT_EQ(seenKeep, afterKeep);
    EXPECT_EQ(movedKeep, 0.0);
    EXPECT_EQ(seen, seenKeep);  // the same clusters and maps before the move
    EXPECT_LT(seenKeep, 90.0);
    EXPECT_GE(after, 90.0);
    EXPECT_NEAR(after, seen + moved, 1e-3);
    EXPECT_GT(reassign, 1.2 * keep);
    EXPECT_LT(reassign / ref1, 1.25);
}

// Second-bounce visibility (issue 29; ours, the paper gathers the second bounce unshadowed):
// own_maps clusters the second-bounce VPLs and gives each cluster its own paraboloid map. Its
// second bounce must lie within [0.7, 1.3] of the same VPLs shaded with exact shadow rays, where
// the unshadowed gather overshoots (measured at 96^2: own_maps 1.05, none 1.93).
TEST_F(GpuSsvp, OwnMapsShadowTheSecondBounceLikeShadowRays) {
    const Scene scene = cornell("spot", 48);
    struct Frame {
        double indirectMean = 0.0, secondExact = 0.0;
        nlohmann::ordered_json stats;
    };
    auto run = [&](const std::map<std::string, std::string>& values) {
        FrameHarness h(*m_ctx, scene, "ssvp", ssvpParams(values), defaultSharedParams());
        h.setup();
        h.warmUp(1);
        h.renderFrame();
        std::vector<ImageLayer> layers = h.readLayers();
        const nlohmann::ordered_json same =
            exp::computeSameVplReference(h, h.scene(), layers, ToneMap{});
        Frame f;
        f.indirectMean = same.at("indirect").at("mean").get<double>();
        if (same.at("by_bounce").contains("2"))
            f.secondExact = same.at("by_bounce").at("2").at("exact_mean").get<double>();
        if (values.count("second_bounce_visibility")) {
            f.stats["second_kmeans_converged"] = stat(h, "second_kmeans_converged");
            f.stats["second_active_clusters"] = stat(h, "second_active_clusters");
        }
        return f;
    };
    const Frame first = run({{"bounces", "1"}});
    const Frame none = run({});
    const Frame own = run({{"second_bounce_visibility", "own_maps"}});
    ASSERT_GT(own.secondExact, 0.0);
    const double ownRatio = (own.indirectMean - first.indirectMean) / own.secondExact;
    const double noneRatio = (none.indirectMean - first.indirectMean) / none.secondExact;
    std::printf("second bounce / same-VPL exact at 48^2: none %.3f, own_maps %.3f\n", noneRatio,
                ownRatio);
    EXPECT_GT(ownRatio, 0.7);
    EXPECT_LT(ownRatio, 1.3);
    EXPECT_GT(noneRatio, 1.3);  // the unshadowed gather: what own_maps corrects
    EXPECT_EQ(own.stats["second_kmeans_converged"].get<double>(), 1.0);
    EXPECT_GT(own.stats["second_active_clusters"].get<double>(), 8.0);
}

TEST_F(GpuSsvp, UnsupportedLightsGiveAReason) {
    const Scene point = cornell("point", 32);
    FrameHarness a(*m_ctx, point, "ssvp", ssvpParams({}), defaultSharedParams());
    EXPECT_FALSE(a.support().supported);
    EXPECT_NE(a.support().reason.find("spot"), std::string::npos) << a.support().reason;
    const Scene spot = cornell("spot", 32);
    FrameHarness b(*m_ctx, spot, "ssvp", ssvpParams({{"light", "3"}}), defaultSharedParams());
    EXPECT_FALSE(b.support().supported);
    EXPECT_NE(b.support().reason.find("light = 3"), std::string::npos) << b.support().reason;
}

void expectParamError(const std::map<std::string, std::string>& values, const std::string& name) {
    ParamSet p = ssvpParams(values);
    try {
        ssvpSettingsFrom(p);
        ADD_FAILURE() << "no error for " << name;
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
}

TEST(CpuSsvpParams, CrossChecksNameTheParameter) {
    expectParamError({{"second_bounce_vpls", "100"}, {"clusters", "8"}}, "second_bounce_vpls");
    expectParamError({{"first_bounce_vpls", "4"}, {"clusters", "8"}}, "first_bounce_vpls");
    expectParamError({{"clusters", "64"}, {"paraboloid_resolution", "2048"}},
                     "paraboloid_resolution");
    // own_maps: C2 second-bounce clusters need C2 VPLs, and count toward the maps' memory.
    expectParamError({{"second_bounce_visibility", "own_maps"},
                      {"second_bounce_vpls", "16"},
                      {"second_bounce_clusters", "32"}},
                     "second_bounce_clusters");
    expectParamError({{"second_bounce_visibility", "own_maps"},
                      {"second_bounce_clusters", "64"},
                      {"paraboloid_resolution", "2048"}},
                     "paraboloid_resolution");
    // Without own_maps (or with one bounce) C2 is unused and not checked.
    EXPECT_NO_THROW(ssvpSettingsFrom(
        ssvpParams({{"second_bounce_vpls", "16"}, {"second_bounce_clusters", "32"}})));
    EXPECT_EQ(
        ssvpSettingsFrom(ssvpParams({{"second_bounce_visibility", "own_maps"}, {"bounces", "1"}}))
            .mapLayers(),
        8u);
    const TechniqueInfo& info = TechniqueRegistry::instance().get("ssvp");
    EXPECT_EQ(info.bouncesParam, "bounces");
    EXPECT_EQ(claimedBounces(info, ssvpParams({{"bounces", "1"}})), 1);
    EXPECT_EQ(claimedBounces(info, ssvpParams({})), 2);
}

}  // namespace
}  // namespace gilab
