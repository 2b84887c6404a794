// experiments/metrics/temporal.cpp: the temporal-instability metric (docs/metrics.md, "Temporal
// instability") on synthetic sequences whose answers are worked out by hand.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/image/color.h"
#include "core/util/error.h"
#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

using namespace gilab;
using namespace gilab::metrics;

namespace {

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr float kInff = std::numeric_limits<float>::infinity();
const double kPi = std::acos(-1.0);

Image grey(int w, int h, float v, int channels = 3) {
    return Image(w, h, channels, v);
}

/** A textured frame that moves with k. */
Image movingFrame(int w, int h, int k) {
    Image im(w, h, 3);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                im.at(x, y, c) = float(0.5 + 0.4 * std::sin(0.3 * (x + 2 * k) + c) *
                                                 std::cos(0.2 * y - 0.1 * k));
            }
        }
    }
    return im;
}

std::vector<const Image*> pointers(const std::vector<Image>& frames) {
    std::vector<const Image*> out;
    for (const Image& f : frames)
        out.push_back(&f);
    return out;
}

/** The message of the gilab::Error f throws ("" if none). */
template <typename F>
std::string errorText(F f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(CpuMetricsTemporal, IdenticalSequenceScoresZeroEvenWhenTheReferenceMoves) {
    std::vector<Image> ref;
    for (int k = 0; k < 5; ++k)
        ref.push_back(movingFrame(24, 16, k));
    const std::vector<Image> test = ref;
    const TemporalResult r = computeTemporalInstability(pointers(test), pointers(ref));
    EXPECT_EQ(r.frames, 5);
    EXPECT_EQ(r.pairs, 4);
    EXPECT_EQ(r.samples, 24u * 16u * 4u);
    EXPECT_EQ(r.skippedPixels, 0u);
    EXPECT_GT(r.level, 0.0);
    EXPECT_EQ(r.meanAbs, 0.0);
    EXPECT_EQ(r.instability, 0.0);
    EXPECT_EQ(r.p95, 0.0);
    ASSERT_EQ(r.map.width(), 24);
    ASSERT_EQ(r.map.height(), 16);
    ASSERT_EQ(r.map.channels(), 1);
    for (float v : r.map.values())
        EXPECT_EQ(v, 0.0f);
    // No stderr images: the noise terms are n/a, and the note says so.
    EXPECT_TRUE(std::isnan(r.noiseFloor));
    EXPECT_TRUE(std::isnan(r.debiased));
    EXPECT_NE(r.note.find("standard-error"), std::string::npos);
}

TEST(CpuMetricsTemporal, FlickerOfKnownAmplitude) {
    const double a = 0.05;
    std::vector<Image> ref, test;
    for (int k = 0; k < 6; ++k) {
        ref.push_back(grey(8, 8, 0.5f));
        test.push_back(grey(8, 8, float(k % 2 == 0 ? 0.5 + a : 0.5 - a)));
    }
    const TemporalResult r = computeTemporalInstability(pointers(test), pointers(ref));
    // Every pair's change is 2a against the reference's 0, relative to the level 0.5.
    EXPECT_EQ(r.pairs, 5);
    EXPECT_NEAR(r.instability, 2.0 * a / 0.5, 1e-6);
    EXPECT_NEAR(r.p95, 2.0 * a / 0.5, 1e-6);
    const double lumScale = double(kLuminanceR) + double(kLuminanceG) + double(kLuminanceB);
    EXPECT_NEAR(r.level, 0.5 * lumScale, 1e-6);
    EXPECT_NEAR(r.meanAbs, 2.0 * a * lumScale, 1e-6);
    EXPECT_NEAR(r.map.at(3, 4, 0), 2.0 * a * lumScale, 1e-6);
    // The same flicker on a moving reference scores the same.
    std::vector<Image> movingRef, movingTest;
    for (int k = 0; k < 6; ++k) {
        movingRef.push_back(movingFrame(8, 8, k));
        Image t = movingRef.back();
        for (float& v : t.values())
            v += float(k % 2 == 0 ? a : -a);
        movingTest.push_back(t);
    }
    const TemporalResult m = computeTemporalInstability(pointers(movingTest), pointers(movingRef));
    EXPECT_NEAR(m.meanAbs, 2.0 * a * lumScale, 1e-6);
}

TEST(CpuMetricsTemporal, LagOnARamp) {
    // A technique that lags one frame (test_k = ref_{k-1}) follows a constant slope exactly:
    // its change equals the reference's, except in the first pair (no earlier frame).
    const int n = 8;
    std::vector<Image> ref, test;
    auto rampValue = [](int k) { return 0.2f + 0.1f * float(std::min(k, 4)); };  // stops at k = 4
    for (int k = 0; k < n; ++k) {
        ref.push_back(grey(6, 5, rampValue(k)));
        test.push_back(grey(6, 5, rampValue(std::max(k - 1, 0))));
    }
    // ref: .2 .3 .4 .5 .6 .6 .6 .6, test: .2 .2 .3 .4 .5 .6 .6 .6. The changes differ by 0.1
    // in the first pair (the lag starts) and the fifth (the ramp stops, the lag catches up).
    const TemporalResult r = computeTemporalInstability(pointers(test), pointers(ref));
    const double level = (0.2 + 0.3 + 0.4 + 0.5 + 4 * 0.6) / 8.0;
    EXPECT_NEAR(r.instability, (2 * 0.1 / 7.0) / level, 1e-6);
    // Two pairs out of seven are wrong: the 95th percentile sees them.
    EXPECT_NEAR(r.p95, 0.1 / level, 1e-6);

    // A lag on a ramp that never changes slope is invisible: the changes match.
    std::vector<Image> ref2, test2;
    for (int k = 0; k < n; ++k) {
        ref2.push_back(grey(6, 5, 0.2f + 0.1f * float(k)));
        test2.push_back(grey(6, 5, 0.2f + 0.1f * float(k - 1)));
    }
    EXPECT_NEAR(computeTemporalInstability(pointers(test2), pointers(ref2)).instability, 0.0, 1e-6);
}

TEST(CpuMetricsTemporal, P95IsTheNearestRankOfAKnownDistribution) {
    // Two frames of 10 × 10 pixels; pixel p's change differs by (q + 1) / 100 of the level,
    // q = 37 p mod 100 (a permutation, so the values are not in pixel order): 1 %, ..., 100 %.
    const Image ref = grey(10, 10, 1.0f);
    Image moved = ref;
    for (size_t p = 0; p < 100; ++p) {
        const float step = float((37 * p) % 100 + 1) / 100.0f;
        for (int c = 0; c < 3; ++c)
            moved.data()[p * 3 + size_t(c)] += step;
    }
    const TemporalResult r = computeTemporalInstability({&ref, &moved}, {&ref, &ref});
    EXPECT_EQ(r.samples, 100u);
    EXPECT_NEAR(r.p95, 0.95, 1e-6);           // the 95th of 100 sorted values
    EXPECT_NEAR(r.instability, 0.505, 1e-6);  // mean of 1 % ... 100 %
}

TEST(CpuMetricsTemporal, NoiseFloorFromConstantStandardErrors) {
    const float s = 0.02f;
    std::vector<Image> ref, test, stderrFrames;
    for (int k = 0; k < 4; ++k) {
        ref.push_back(movingFrame(16, 16, k));
        test.push_back(ref.back());
        stderrFrames.push_back(grey(16, 16, s));
    }
    const std::vector<const Image*> stderrPtrs = pointers(stderrFrames);
    const TemporalResult r = computeTemporalInstability(pointers(test), pointers(ref), &stderrPtrs);
    // Luminance standard error of independent channels, then s² = σ_k² + σ_{k+1}².
    const double wr = kLuminanceR, wg = kLuminanceG, wb = kLuminanceB;
    const double sigmaY = double(s) * std::sqrt(wr * wr + wg * wg + wb * wb);
    const double expected = std::sqrt(2.0) * sigmaY * std::sqrt(2.0 / kPi) / r.level;
    EXPECT_NEAR(r.noiseFloor, expected, 1e-9);
    EXPECT_EQ(r.instability, 0.0);
    EXPECT_EQ(r.debiased, 0.0);

    // A flicker well above the floor: debiased = raw − floor.
    std::vector<Image> flicker = test;
    for (size_t k = 0; k < flicker.size(); ++k) {
        for (float& v : flicker[k].values())
            v += (k % 2 == 0) ? 0.1f : -0.1f;
    }
    const TemporalResult f =
        computeTemporalInstability(pointers(flicker), pointers(ref), &stderrPtrs);
    EXPECT_NEAR(f.noiseFloor, expected, 1e-9);
    EXPECT_NEAR(f.debiased, f.instability - f.noiseFloor, 1e-12);
    EXPECT_GT(f.debiased, 0.0);
}

TEST(CpuMetricsTemporal, AnExactTechniqueAgainstANoisyReferenceScoresTheNoiseFloor) {
    // Reference frames = truth + independent N(0, σ) per channel; the technique renders the
    // truth. Its raw score is then pure reference noise, close to the floor, debiased ≈ 0.
    const float sigma = 0.03f;
    detail::NormalRng rng(7);
    std::vector<Image> truth, noisy, stderrFrames;
    for (int k = 0; k < 5; ++k) {
        truth.push_back(movingFrame(64, 64, k));
        Image n = truth.back();
        for (float& v : n.values())
            v += sigma * float(rng.next());
        noisy.push_back(n);
        stderrFrames.push_back(grey(64, 64, sigma));
    }
    const std::vector<const Image*> stderrPtrs = pointers(stderrFrames);
    const TemporalResult r =
        computeTemporalInstability(pointers(truth), pointers(noisy), &stderrPtrs);
    EXPECT_NEAR(r.instability / r.noiseFloor, 1.0, 0.03);
    EXPECT_LT(r.debiased, 0.03 * r.noiseFloor);
}

TEST(CpuMetricsTemporal, FewerThanTwoFramesIsNotAnError) {
    const Image a = grey(4, 4, 0.5f);
    for (const TemporalResult& r :
         {computeTemporalInstability({}, {}), computeTemporalInstability({&a}, {&a})}) {
        EXPECT_EQ(r.pairs, 0);
        EXPECT_EQ(r.samples, 0u);
        EXPECT_TRUE(std::isnan(r.instability));
        EXPECT_TRUE(std::isnan(r.p95));
        EXPECT_TRUE(std::isnan(r.level));
        EXPECT_TRUE(r.map.empty());
        EXPECT_NE(r.note.find("fewer than 2 frames"), std::string::npos);
        const nlohmann::ordered_json j = toJson(r);
        EXPECT_TRUE(j["temporal_instability"].is_null());
        EXPECT_EQ(j["pairs"].get<int>(), 0);
    }
}

TEST(CpuMetricsTemporal, MismatchesThrowNamingTheFrame) {
    const Image a = grey(8, 8, 0.5f), small = grey(8, 6, 0.5f), mono = grey(8, 8, 0.5f, 1);
    EXPECT_NE(errorText([&] {
                  computeTemporalInstability({&a, &a, &small}, {&a, &a, &a});
              }).find("test frame 2 is 8x6, reference frame 0 is 8x8"),
              std::string::npos);
    EXPECT_NE(errorText([&] {
                  computeTemporalInstability({&a, &a}, {&a, &mono});
              }).find("reference frame 1 has 1 channels"),
              std::string::npos);
    EXPECT_NE(errorText([&] {
                  computeTemporalInstability({&a, &a}, {&a, &a, &a});
              }).find("2 test frames but 3 reference frames"),
              std::string::npos);
    EXPECT_NE(errorText([&] {
                  computeTemporalInstability({&a, nullptr}, {&a, &a});
              }).find("test frame 1 is null"),
              std::string::npos);
    const std::vector<const Image*> stderrBad = {&a, &small};
    EXPECT_NE(errorText([&] {
                  computeTemporalInstability({&a, &a}, {&a, &a}, &stderrBad);
              }).find("reference standard-error frame 1 is 8x6"),
              std::string::npos);
    const Mask wrongMask(4, 4, true);
    EXPECT_NE(errorText([&] {
                  computeTemporalInstability({&a, &a}, {&a, &a}, nullptr, &wrongMask);
              }).find("mask is 4x4"),
              std::string::npos);
}

TEST(CpuMetricsTemporal, NonFinitePixelsAreSkippedAndCounted) {
    const double a = 0.05;
    std::vector<Image> ref, test;
    for (int k = 0; k < 3; ++k) {
        ref.push_back(grey(8, 8, 0.5f));
        test.push_back(grey(8, 8, float(k % 2 == 0 ? 0.5 + a : 0.5 - a)));
    }
    test[1].at(3, 3, 1) = kNaNf;  // in pairs 0 and 1
    ref[0].at(4, 4, 2) = kInff;   // in pair 0 only
    const TemporalResult r = computeTemporalInstability(pointers(test), pointers(ref));
    EXPECT_EQ(r.skippedPixels, 3u);
    EXPECT_EQ(r.samples, 64u * 2u - 3u);
    EXPECT_NEAR(r.instability, 2.0 * a / 0.5, 1e-6);  // the rest is unaffected
    EXPECT_TRUE(std::isfinite(r.level));
    EXPECT_TRUE(std::isnan(r.map.at(3, 3, 0)));     // no finite pair
    EXPECT_TRUE(std::isfinite(r.map.at(4, 4, 0)));  // pair 1 is finite
    EXPECT_NE(r.note.find("3 (pixel, pair) samples left out"), std::string::npos);
    EXPECT_EQ(toJson(r)["skipped_pixels"].get<size_t>(), 3u);
}

TEST(CpuMetricsTemporal, ZeroReferenceLevelGivesNaNRelativeValues) {
    std::vector<Image> ref, test;
    for (int k = 0; k < 3; ++k) {
        ref.push_back(grey(4, 4, 0.0f));
        test.push_back(grey(4, 4, k % 2 == 0 ? 0.1f : 0.0f));
    }
    const TemporalResult r = computeTemporalInstability(pointers(test), pointers(ref));
    EXPECT_EQ(r.level, 0.0);
    EXPECT_GT(r.meanAbs, 0.0);  // the absolute value is still there
    EXPECT_TRUE(std::isnan(r.instability));
    EXPECT_TRUE(std::isnan(r.p95));
    EXPECT_NE(r.note.find("level"), std::string::npos);
    EXPECT_TRUE(toJson(r)["temporal_instability"].is_null());
}

TEST(CpuMetricsTemporal, MaskRestrictsThePooling) {
    // The test flickers on the left half only.
    const double a = 0.05;
    std::vector<Image> ref, test;
    for (int k = 0; k < 4; ++k) {
        ref.push_back(grey(8, 8, 0.5f));
        Image t = grey(8, 8, 0.5f);
        for (int y = 0; y < 8; ++y) {
            for (int x = 0; x < 4; ++x) {
                for (int c = 0; c < 3; ++c)
                    t.at(x, y, c) = float(k % 2 == 0 ? 0.5 + a : 0.5 - a);
            }
        }
        test.push_back(t);
    }
    const Mask left = Mask::fromRects(8, 8, {PixelRect{0, 0, 4, 8}});
    const Mask right = left.inverted();
    const TemporalResult l =
        computeTemporalInstability(pointers(test), pointers(ref), nullptr, &left);
    const TemporalResult rr =
        computeTemporalInstability(pointers(test), pointers(ref), nullptr, &right);
    const TemporalResult all = computeTemporalInstability(pointers(test), pointers(ref));
    EXPECT_EQ(l.regionPixels, 32u);
    EXPECT_EQ(l.samples, 32u * 3u);
    EXPECT_NEAR(l.instability, 2.0 * a / 0.5, 1e-6);
    EXPECT_NEAR(rr.instability, 0.0, 1e-9);
    EXPECT_NEAR(all.instability, a / 0.5, 1e-6);
    // The map covers the whole image whatever the mask.
    EXPECT_GT(rr.map.at(1, 1, 0), 0.0f);
}

TEST(CpuMetricsTemporal, JsonKeysAndMapPng) {
    std::vector<Image> ref, test;
    for (int k = 0; k < 3; ++k) {
        ref.push_back(movingFrame(12, 12, k));
        test.push_back(movingFrame(12, 12, k % 2));
    }
    const TemporalResult r = computeTemporalInstability(pointers(test), pointers(ref));
    const nlohmann::ordered_json j = toJson(r);
    std::vector<std::string> keys;
    for (auto it = j.begin(); it != j.end(); ++it)
        keys.push_back(it.key());
    const std::vector<std::string> expected = {
        "frames",   "pairs",    "region_pixels",        "samples", "skipped_pixels",
        "level",    "mean_abs", "temporal_instability", "p95",     "noise_floor",
        "debiased", "note"};
    EXPECT_EQ(keys, expected);
    EXPECT_GT(j["temporal_instability"].get<double>(), 0.0);

    const std::filesystem::path png =
        std::filesystem::temp_directory_path() / "gilab_temporal_metric_test_map.png";
    std::filesystem::remove(png);
    writeTemporalMapPng(png.string(), r);
    EXPECT_TRUE(std::filesystem::exists(png));
    std::filesystem::remove(png);
    EXPECT_THROW(writeTemporalMapPng(png.string(), TemporalResult{}), Error);
}
