// experiments/metrics: MSE, relMSE, PSNR, SSIM, FLIP, regions, non-finite policy, error bars,
// magma. Small synthetic images with answers worked out by hand (docs/metrics.md).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

#include "core/image/color.h"
#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

using namespace gilab;
using namespace gilab::metrics;

namespace {

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr float kInff = std::numeric_limits<float>::infinity();

Image constantImage(int w, int h, float r, float g, float b) {
    Image im(w, h, 3);
    for (size_t p = 0; p < im.pixelCount(); ++p) {
        im.data()[p * 3 + 0] = r;
        im.data()[p * 3 + 1] = g;
        im.data()[p * 3 + 2] = b;
    }
    return im;
}

/** A deterministic textured image with values in [lo, lo + range]. */
Image patternImage(int w, int h, float lo, float range, uint64_t seed) {
    Image im(w, h, 3);
    detail::NormalRng rng(seed);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                const double smooth = 0.5 + 0.25 * std::sin(0.4 * x + c) * std::cos(0.3 * y);
                const double noise = 0.1 * rng.next();
                im.at(x, y, c) = lo + range * float(std::clamp(smooth + noise, 0.0, 1.0));
            }
        }
    }
    return im;
}

Image addNoise(const Image& im, float amplitude, uint64_t seed) {
    Image out = im;
    detail::NormalRng rng(seed);
    for (float& v : out.values())
        v = std::max(0.0f, v + amplitude * float(rng.next()));
    return out;
}

/** A 48×48 grey (sRGB 0.5) image with a 12×12 square of grey 0.5 + d in the middle. */
Image squareSrgb(float d) {
    Image im = constantImage(48, 48, 0.5f, 0.5f, 0.5f);
    for (int y = 18; y < 30; ++y) {
        for (int x = 18; x < 30; ++x) {
            for (int c = 0; c < 3; ++c)
                im.at(x, y, c) = 0.5f + d;
        }
    }
    return im;
}

}  // namespace

// ------------------------------------------------------------------------------------------

TEST(CpuMetricsPixel, IdenticalImagesGiveZeroError) {
    const Image ref = patternImage(32, 32, 0.0f, 2.0f, 1);
    const MetricSet m = computeMetrics(ref, ref, MetricOptions{});
    EXPECT_EQ(m.mse, 0.0);
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_EQ(m.relMse, 0.0);
    EXPECT_EQ(m.psnrLdr, kInf);  // +inf in the struct, null in JSON
    EXPECT_EQ(m.psnrHdr, kInf);
    EXPECT_NEAR(m.ssim, 1.0, 1e-6);
    EXPECT_EQ(m.flip.mean, 0.0);
    EXPECT_EQ(m.flip.max, 0.0);
    EXPECT_EQ(m.flipLdr.max, 0.0);
    EXPECT_EQ(m.pixels, 32u * 32u);
    EXPECT_FALSE(m.hasNonFinite);
    const auto j = toJson(m);
    EXPECT_TRUE(j["psnr_ldr"].is_null());
    EXPECT_TRUE(j["psnr_hdr"].is_null());
    EXPECT_TRUE(j["error_bars"].is_null());
    EXPECT_EQ(j["mse"].get<double>(), 0.0);
}

TEST(CpuMetricsPixel, ShiftOnOneChannel) {
    // Reference grey 0.5 with one pixel at 2.0 (the HDR peak); test = ref + 1/8 on R.
    Image ref = constantImage(16, 16, 0.5f, 0.5f, 0.5f);
    for (int c = 0; c < 3; ++c)
        ref.at(3, 4, c) = 2.0f;
    Image test = ref;
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x)
            test.at(x, y, 0) += 0.125f;
    }
    const double delta2 = 0.125 * 0.125;
    EXPECT_DOUBLE_EQ(computeMse(test, ref).value, delta2 / 3.0);
    EXPECT_DOUBLE_EQ(computeRmse(test, ref).value, std::sqrt(delta2 / 3.0));
    EXPECT_DOUBLE_EQ(getHdrPeak(ref), 2.0);
    // 10 log10(2² / (1/64 / 3)) = 10 log10(768) = 28.8536 dB.
    EXPECT_NEAR(computePsnrHdr(test, ref).value, 28.853612200315, 1e-9);
    EXPECT_NEAR(computePsnrHdr(test, ref, nullptr, 1.0).value, 10.0 * std::log10(192.0), 1e-9);
}

TEST(CpuMetricsPixel, PsnrLdrByHand) {
    // Test R encodes to sRGB 0.2 = 51/255 after tonemapping, the reference is black:
    // MSE_8bit = 51² / 3 = 867, PSNR = 10 log10(255² / 867) = 10 log10(75) = 18.7506 dB.
    const Image ref = constantImage(16, 16, 0.0f, 0.0f, 0.0f);
    const Image test = constantImage(16, 16, srgbToLinear(0.2f), 0.0f, 0.0f);
    EXPECT_NEAR(computePsnrLdr(test, ref, ToneMap{}).value, 10.0 * std::log10(75.0), 1e-9);
    // One stop of exposure on a test half as bright gives the same display values.
    const Image half = constantImage(16, 16, 0.5f * srgbToLinear(0.2f), 0.0f, 0.0f);
    EXPECT_NEAR(computePsnrLdr(half, ref, ToneMap{1.0f}).value, 10.0 * std::log10(75.0), 1e-9);
}

TEST(CpuMetricsPixel, RelativeMseByHand) {
    // Left half: r = 0.1, t = 0.2: 0.01 / (0.01 + 0.01) = 0.5.
    // Right half: r = 1, t = 1.5: 0.25 / (1 + 0.01) = 0.247524752...  Mean: 0.373762376...
    Image ref(16, 16, 3), test(16, 16, 3);
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x) {
            for (int c = 0; c < 3; ++c) {
                ref.at(x, y, c) = x < 8 ? 0.1f : 1.0f;
                test.at(x, y, c) = x < 8 ? 0.2f : 1.5f;
            }
        }
    }
    EXPECT_NEAR(computeRelMse(test, ref).value, 0.5 * (0.5 + 0.25 / 1.01), 1e-7);
}

TEST(CpuMetricsPixel, EnergyRatio) {
    const Image ref = patternImage(16, 16, 0.1f, 1.0f, 2);
    Image test = ref;
    for (float& v : test.values())
        v *= 0.5f;
    EXPECT_NEAR(computeEnergyRatio(test, ref), 0.5, 1e-6);
    EXPECT_TRUE(std::isnan(computeEnergyRatio(ref, constantImage(16, 16, 0, 0, 0))));
}

// ------------------------------------------------------------------------------------------

TEST(CpuMetricsSsim, ConstantImagesByHand) {
    // σ = 0: SSIM = (2ab + C1) / (a² + b² + C1) = 0.2501 / 0.3126 for a = 0.5, b = 0.25.
    Image a(16, 16, 1, 0.5f), b(16, 16, 1, 0.25f);
    const SsimResult s = computeSsimLuma(a, b);
    EXPECT_NEAR(s.mean.value, 0.2501 / 0.3126, 1e-5);
    EXPECT_EQ(s.map.width(), 6);
    EXPECT_EQ(s.map.height(), 6);
    EXPECT_EQ(s.mean.pixels, 36u);
}

TEST(CpuMetricsSsim, DecreasesWithNoiseAndIsSymmetric) {
    const Image ref = patternImage(48, 48, 0.05f, 0.6f, 3);
    double previous = 1.0;
    for (float amplitude : {0.005f, 0.02f, 0.08f, 0.3f}) {
        const Image test = addNoise(ref, amplitude, 4);
        const double s = computeSsim(test, ref, ToneMap{}).mean.value;
        EXPECT_LT(s, previous) << "noise " << amplitude;
        previous = s;
        EXPECT_EQ(s, computeSsim(ref, test, ToneMap{}).mean.value);  // exactly symmetric
    }
    EXPECT_LT(previous, 0.5);
}

// ------------------------------------------------------------------------------------------

TEST(CpuMetricsFlip, EqualImagesGiveZero) {
    const Image srgb = squareSrgb(0.3f);
    const FlipResult ldr = computeLdrFlip(srgb, srgb);
    EXPECT_EQ(ldr.stats.max, 0.0);
    EXPECT_EQ(ldr.stats.mean, 0.0);
    EXPECT_EQ(ldr.stats.weightedMedian, 0.0);
    const Image hdr = patternImage(32, 32, 0.0f, 20.0f, 5);
    const FlipResult h = computeHdrFlip(hdr, hdr);
    EXPECT_EQ(h.stats.max, 0.0);
    EXPECT_EQ(h.stats.pixels, 32u * 32u);
}

TEST(CpuMetricsFlip, UniformImagesMatchTheColourPipelineByHand) {
    // Uniform images: filtering keeps them uniform and the feature error is 0, so FLIP is the
    // colour term. Black vs white: HyAB = 100, 100^0.7 = 25.119; cmax = 41.275 (Hunt-adjusted
    // green (87.73, -86.18, 83.18) vs blue (32.30, 79.19, -107.86)); 25.119 > 0.4 cmax, so
    // 0.95 + (25.119 - 16.510) / (41.275 - 16.510) * 0.05 = 0.96738.
    const Image black = constantImage(24, 24, 0, 0, 0), white = constantImage(24, 24, 1, 1, 1);
    EXPECT_NEAR(detail::getMaxColorError(), 41.2755, 1e-3);
    const FlipResult bw = computeLdrFlip(black, white);
    EXPECT_NEAR(bw.stats.min, 0.96738, 2e-4);
    EXPECT_NEAR(bw.stats.max, 0.96738, 2e-4);
    // sRGB grey 0.5 vs 0.6: HyAB^0.7 = 4.9534 < 0.4 cmax, so 0.95 / 16.510 * 4.9534 = 0.28502.
    const Image g5 = constantImage(24, 24, 0.5f, 0.5f, 0.5f);
    const Image g6 = constantImage(24, 24, 0.6f, 0.6f, 0.6f);
    EXPECT_NEAR(computeLdrFlip(g5, g6).stats.mean, 0.28502, 2e-4);
    double lab[3];
    detail::linearRgbToHuntLab(1.0, 1.0, 1.0, lab);
    EXPECT_NEAR(lab[0], 100.0, 1e-3);
    EXPECT_NEAR(lab[1], 0.0, 1e-3);
    EXPECT_NEAR(lab[2], 0.0, 1e-3);
}

TEST(CpuMetricsFlip, GrowsWithContrastOfASquare) {
    const Image ref = squareSrgb(0.0f);
    double prevMean = 0.0, prevMax = 0.0;
    for (float d : {0.02f, 0.05f, 0.1f, 0.2f, 0.4f}) {
        const FlipResult r = computeLdrFlip(squareSrgb(d), ref);
        EXPECT_GT(r.stats.mean, prevMean) << "d = " << d;
        EXPECT_GT(r.stats.max, prevMax) << "d = " << d;
        EXPECT_LE(r.stats.max, 1.0);
        EXPECT_GE(r.stats.min, 0.0);
        prevMean = r.stats.mean;
        prevMax = r.stats.max;
    }
}

TEST(CpuMetricsFlip, LdrFlipIsSymmetric) {
    // HyAB and the feature difference are symmetric, and both images go through the same
    // pipeline, so LDR-FLIP(a, b) = LDR-FLIP(b, a) pixel for pixel.
    const Image a = patternImage(32, 32, 0.0f, 1.0f, 6);
    const Image b = addNoise(a, 0.1f, 7);
    const FlipResult ab = computeLdrFlip(a, b), ba = computeLdrFlip(b, a);
    ASSERT_EQ(ab.errorMap.values().size(), ba.errorMap.values().size());
    for (size_t i = 0; i < ab.errorMap.values().size(); ++i) {
        EXPECT_EQ(ab.errorMap.values()[i], ba.errorMap.values()[i]) << i;
    }
    EXPECT_GT(ab.stats.mean, 0.0);
}

TEST(CpuMetricsFlip, WeightedPercentilesByHand) {
    // Values 0.1, 0.2, 0.3, 0.4 (sum 1.0): cumulative 0.1, 0.3, 0.6, 1.0.
    Image map(4, 1, 1);
    map.values() = {0.3f, 0.1f, 0.4f, 0.2f};
    const FlipStats s = poolFlip(map);
    EXPECT_NEAR(s.mean, 0.25, 1e-7);
    EXPECT_FLOAT_EQ(float(s.weightedP25), 0.2f);
    EXPECT_FLOAT_EQ(float(s.weightedMedian), 0.3f);
    EXPECT_FLOAT_EQ(float(s.weightedP75), 0.4f);
    EXPECT_FLOAT_EQ(float(s.min), 0.1f);
    EXPECT_FLOAT_EQ(float(s.max), 0.4f);
}

TEST(CpuMetricsFlip, HdrExposuresFromTheReference) {
    // t⁻¹(0.85) = 2.11887 (the ACES fit with its 0.6 pre-scale, solved by hand). Luminance:
    // max 50, median 1 (120 pixels at 0.25, 135 at 1, one at 50).
    const double tInv = hdrFlipToneMapInverse(0.85);
    EXPECT_NEAR(tInv, 2.118872, 1e-5);
    EXPECT_NEAR(hdrFlipToneMap(tInv), 0.85, 1e-12);
    Image ref(16, 16, 3);
    for (size_t p = 0; p < ref.pixelCount(); ++p) {
        const float v = p < 120 ? 0.25f : (p == 255 ? 50.0f : 1.0f);
        for (int c = 0; c < 3; ++c)
            ref.data()[p * 3 + size_t(c)] = v;
    }
    const HdrExposures ex = computeHdrExposures(ref);
    EXPECT_NEAR(ex.start, std::log2(2.118872 / 50.0), 1e-5);  // -4.5606
    EXPECT_NEAR(ex.stop, std::log2(2.118872), 1e-5);          // 1.0833
    EXPECT_EQ(ex.count, 6);                                   // ceil(5.644)
    const Image test = addNoise(ref, 0.05f, 8);
    const FlipResult r = computeHdrFlip(test, ref);
    EXPECT_EQ(r.exposureCount, 6);
    EXPECT_DOUBLE_EQ(r.startExposure, ex.start);
    EXPECT_GT(r.stats.mean, 0.0);
    EXPECT_GE(r.stats.min, 0.0);
    EXPECT_LE(r.stats.max, 1.0);
    // HDR-FLIP is the per-pixel max over exposures: at least LDR-FLIP at any one of them.
    const double c4 = ex.start + 4 * (ex.stop - ex.start) / (ex.count - 1);
    const FlipResult single = computeHdrFlip(
        test, ref, HdrFlipOptions{.startExposure = c4, .stopExposure = c4, .exposureCount = 1});
    for (size_t p = 0; p < ref.pixelCount(); ++p) {
        EXPECT_GE(r.errorMap.data()[p], single.errorMap.data()[p]);
    }
}

namespace {

/** The synthetic pair used to cross-check against the FLIP authors' tool (v1.6). */
void makeToolCheckImages(Image& a, Image& b, Image& c, Image& hdrRef, Image& hdrTest) {
    const int w = 64, h = 48;
    detail::NormalRng rng(3);
    a = Image(w, h, 3), b = Image(w, h, 3), c = Image(w, h, 3);
    auto quantize = [](double v) {
        return float(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)) / 255.0f;
    };
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            for (int ch = 0; ch < 3; ++ch) {
                const double base =
                    0.5 + 0.3 * std::sin(0.3 * x + ch) * std::cos(0.2 * y + 0.5 * ch);
                a.at(x, y, ch) = quantize(float(base));
                b.at(x, y, ch) = quantize(float(std::clamp(base + 0.08 * rng.next(), 0.0, 1.0)));
                const bool square = x > 20 && x < 40 && y > 10 && y < 30;
                c.at(x, y, ch) = quantize(float(square ? (ch == 0 ? 0.9 : 0.2) : base));
            }
        }
    }
    hdrRef = Image(w, h, 3), hdrTest = Image(w, h, 3);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            for (int ch = 0; ch < 3; ++ch) {
                double base = 0.3 * std::exp(2.0 * std::sin(0.15 * x + ch) * std::cos(0.1 * y));
                if (x > 50 && y < 8) base = 60.0;
                if (x < 10) base *= 0.01;
                hdrRef.at(x, y, ch) = float(base);
                hdrTest.at(x, y, ch) = float(std::max(0.0, base * (1.0 + 0.15 * rng.next())));
            }
        }
    }
}

}  // namespace

TEST(CpuMetricsFlip, MatchesTheAuthorsToolOnSyntheticImages) {
    // Expected values printed by the FLIP authors' tool (v1.6, run outside this repository on
    // the same images written as 8-bit PNG / float EXR). Per-pixel maps agreed to 1/255.
    Image a, b, c, hdrRef, hdrTest;
    makeToolCheckImages(a, b, c, hdrRef, hdrTest);
    const FlipStats noise = computeLdrFlip(b, a).stats;
    EXPECT_NEAR(noise.mean, 0.163250, 1e-4);
    EXPECT_NEAR(noise.weightedMedian, 0.178587, 1e-4);
    EXPECT_NEAR(noise.weightedP25, 0.139795, 1e-4);
    EXPECT_NEAR(noise.weightedP75, 0.223161, 1e-4);
    EXPECT_NEAR(noise.min, 0.014693, 1e-4);
    EXPECT_NEAR(noise.max, 0.448657, 1e-4);
    const FlipStats square = computeLdrFlip(c, a).stats;
    EXPECT_NEAR(square.mean, 0.133492, 1e-4);
    EXPECT_NEAR(square.weightedMedian, 0.849216, 1e-4);
    EXPECT_NEAR(square.weightedP25, 0.618556, 1e-4);
    EXPECT_NEAR(square.weightedP75, 0.941987, 2e-4);
    EXPECT_NEAR(square.max, 0.973838, 1e-4);
    const FlipResult hdr = computeHdrFlip(hdrTest, hdrRef);
    EXPECT_NEAR(hdr.startExposure, -4.8236, 1e-4);
    EXPECT_NEAR(hdr.stopExposure, 2.8515, 1e-4);
    EXPECT_EQ(hdr.exposureCount, 8);
    EXPECT_NEAR(hdr.stats.mean, 0.096557, 1e-4);
    EXPECT_NEAR(hdr.stats.weightedMedian, 0.113136, 1e-4);
    EXPECT_NEAR(hdr.stats.weightedP25, 0.086989, 1e-4);
    EXPECT_NEAR(hdr.stats.weightedP75, 0.146100, 1e-4);
    EXPECT_NEAR(hdr.stats.min, 0.000974, 1e-4);
    EXPECT_NEAR(hdr.stats.max, 0.286064, 1e-4);
}

// ------------------------------------------------------------------------------------------

TEST(CpuMetricsRegions, MaskRestrictsThePixelCount) {
    const Image ref = patternImage(32, 32, 0.1f, 1.0f, 9);
    Image test = ref;
    test.at(0, 0, 0) += 1.0f;  // an error outside the region
    const Mask rect = Mask::fromRects(32, 32, {{4, 4, 10, 6}});
    EXPECT_EQ(rect.count(), 60u);
    const ScalarResult mse = computeMse(test, ref, &rect);
    EXPECT_EQ(mse.pixels, 60u);
    EXPECT_EQ(mse.value, 0.0);
    EXPECT_GT(computeMse(test, ref).value, 0.0);
    EXPECT_EQ(Mask::fromRects(32, 32, {{28, 28, 10, 10}}).count(), 16u);  // clipped
    EXPECT_EQ(Mask::fromNormalizedRects(32, 32, {{0.0, 0.0, 0.5, 0.25}}).count(), 128u);
    EXPECT_EQ(rect.inverted().count(), 32u * 32u - 60u);

    MetricOptions options;
    options.mask = rect;
    const MetricSet m = computeMetrics(test, ref, options);
    EXPECT_EQ(m.pixels, 60u);
    EXPECT_EQ(m.regionPixels, 60u);
    EXPECT_EQ(m.flip.pixels, 60u);
    // SSIM windows whose centre is in the region and inside [5, 26]²: x 5..13, y 5..9.
    EXPECT_EQ(computeSsim(test, ref, ToneMap{}, &rect).mean.pixels, 45u);
}

TEST(CpuMetricsRegions, IndirectFractionMask) {
    Image full = constantImage(16, 16, 1, 1, 1), indirect(16, 16, 3);
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x) {
            for (int c = 0; c < 3; ++c)
                indirect.at(x, y, c) = x < 8 ? 0.3f : 0.7f;
        }
    }
    for (int c = 0; c < 3; ++c)
        full.at(15, 15, c) = 0.0f;  // black: never in the region
    const Mask m = Mask::fromIndirectFraction(indirect, full, 50.0);
    EXPECT_EQ(m.count(), 8u * 16u - 1u);
    EXPECT_FALSE(m.at(0, 0));
    EXPECT_TRUE(m.at(8, 0));
    EXPECT_EQ(Mask::fromIndirectFraction(indirect, full, 20.0).count(), 16u * 16u - 1u);
}

// ------------------------------------------------------------------------------------------

TEST(CpuMetricsNonFinite, CountedExcludedAndFlagged) {
    const Image ref0 = constantImage(16, 16, 0.5f, 0.5f, 0.5f);
    Image ref = ref0, test = ref0;
    for (float& v : test.values())
        v += 0.125f;
    test.at(1, 1, 0) = kNaNf;
    test.at(2, 1, 1) = kNaNf;
    test.at(3, 1, 2) = kInff;
    ref.at(5, 5, 0) = kInff;
    ref.at(6, 5, 2) = kNaNf;
    const ScalarResult mse = computeMse(test, ref);
    EXPECT_EQ(mse.testNonFinite, 3u);
    EXPECT_EQ(mse.refNonFinite, 2u);
    EXPECT_EQ(mse.pixels, 256u - 5u);
    EXPECT_TRUE(mse.hasNonFinite());
    EXPECT_DOUBLE_EQ(mse.value, 0.125 * 0.125);  // every finite pixel has the same error

    MetricSet m;
    MetricMaps maps;
    m = computeMetrics(test, ref, MetricOptions{}, &maps);
    EXPECT_TRUE(m.hasNonFinite);
    EXPECT_EQ(m.testNonFinite, 3u);
    EXPECT_EQ(m.refNonFinite, 2u);
    EXPECT_EQ(m.pixels, 251u);
    EXPECT_DOUBLE_EQ(m.mse, 0.125 * 0.125);
    EXPECT_TRUE(std::isfinite(m.ssim));
    EXPECT_TRUE(std::isfinite(m.flip.mean));
    EXPECT_EQ(m.flip.pixels, 251u);
    EXPECT_TRUE(std::isnan(maps.flip.at(1, 1, 0)));
    EXPECT_TRUE(std::isnan(maps.flipLdr.at(5, 5, 0)));
    EXPECT_TRUE(std::isfinite(maps.flip.at(0, 0, 0)));
    EXPECT_TRUE(toJson(m)["has_non_finite"].get<bool>());
}

// ------------------------------------------------------------------------------------------

TEST(CpuMetricsErrorBars, ExactImageIsWithinReferenceNoise) {
    const float sigma = 0.02f;
    const Image ref = patternImage(32, 32, 0.2f, 1.0f, 10);
    const Image stdError = constantImage(32, 32, sigma, sigma, sigma);
    MetricOptions options;
    options.referenceStdError = &stdError;
    const MetricSet m = computeMetrics(ref, ref, options);
    EXPECT_EQ(m.mse, 0.0);
    EXPECT_TRUE(m.bars.available);
    EXPECT_EQ(m.bars.resamples, 8);
    EXPECT_NEAR(m.bars.mseNoiseFloor, double(sigma) * sigma, 1e-12);
    EXPECT_TRUE(m.withinReferenceNoise);
    EXPECT_TRUE(m.bars.ssim.withinNoise);
    EXPECT_TRUE(m.bars.flip.withinNoise);
    EXPECT_TRUE(m.bars.psnrHdr.withinNoise);
    EXPECT_GT(m.bars.flip.floorMean, 0.0);
    EXPECT_FALSE(toJson(m)["error_bars"].is_null());
}

TEST(CpuMetricsErrorBars, TenSigmaShiftIsDistinguishable) {
    const float sigma = 0.02f;
    const Image ref = patternImage(32, 32, 0.2f, 1.0f, 10);
    const Image stdError = constantImage(32, 32, sigma, sigma, sigma);
    Image test = ref;
    for (float& v : test.values())
        v += 10.0f * sigma;
    MetricOptions options;
    options.referenceStdError = &stdError;
    const MetricSet m = computeMetrics(test, ref, options);
    const double s2 = double(sigma) * sigma;
    const double shift = double(ref.values()[0] + 10.0f * sigma) - double(ref.values()[0]);
    EXPECT_NEAR(m.mse, 100.0 * s2, 1e-8);
    EXPECT_NEAR(m.bars.mseDebiased, m.mse - s2, 1e-8);
    // ±1σ: sqrt(K (4 d² σ² + 2 σ⁴)) / K with d² = MSE − σ², K = 3 · 1024.
    const double k = 3.0 * 1024.0;
    const double d2 = shift * shift - s2;
    EXPECT_NEAR(m.bars.mseSigma, std::sqrt(k * (4.0 * d2 * s2 + 2.0 * s2 * s2)) / k, 1e-7);
    EXPECT_FALSE(m.withinReferenceNoise);
    EXPECT_FALSE(m.bars.psnrHdr.withinNoise);
    EXPECT_FALSE(m.bars.flip.withinNoise);
    EXPECT_GT(m.bars.flip.spread, 0.0);
}

TEST(CpuMetricsErrorBars, NoiseFloorIsMeanVarianceAndDeterministic) {
    const Image ref = patternImage(16, 16, 0.2f, 1.0f, 11);
    Image stdError(16, 16, 3);
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x) {
            for (int c = 0; c < 3; ++c)
                stdError.at(x, y, c) = x < 8 ? 0.01f : 0.03f;
        }
    }
    MetricOptions options;
    options.referenceStdError = &stdError;
    options.resampleFlip = false;
    const Image test = addNoise(ref, 0.01f, 12);
    const MetricSet a = computeMetrics(test, ref, options);
    const MetricSet b = computeMetrics(test, ref, options);
    EXPECT_NEAR(a.bars.mseNoiseFloor, 0.5 * (1e-4 + 9e-4), 1e-10);
    EXPECT_EQ(a.bars.ssim.spread, b.bars.ssim.spread);
    EXPECT_EQ(a.bars.psnrLdr.floorMean, b.bars.psnrLdr.floorMean);
    EXPECT_TRUE(std::isnan(a.bars.flip.spread));  // not resampled
    // A shared noise floor (one per reference) gives the same bars as computing it inline.
    const NoiseFloorSamples floor = computeNoiseFloor(ref, options);
    options.noiseFloor = &floor;
    const MetricSet c = computeMetrics(test, ref, options);
    EXPECT_EQ(c.bars.ssim.floorMean, a.bars.ssim.floorMean);
    EXPECT_EQ(c.bars.ssim.spread, a.bars.ssim.spread);
    EXPECT_EQ(c.bars.psnrHdr.floorSpread, a.bars.psnrHdr.floorSpread);
    EXPECT_EQ(c.bars.psnrLdr.withinNoise, a.bars.psnrLdr.withinNoise);
}

// ------------------------------------------------------------------------------------------

TEST(CpuMetricsColormap, MagmaEndpointsAndLightness) {
    float rgb[3];
    getMagmaSrgb(0.0, rgb);  // black-ish purple
    EXPECT_LT(rgb[0], 0.02f);
    EXPECT_LT(rgb[1], 0.02f);
    EXPECT_LT(rgb[2], 0.03f);
    EXPECT_GT(rgb[2], rgb[0]);
    getMagmaSrgb(1.0, rgb);  // light yellow (0.987, 0.991, 0.750)
    EXPECT_NEAR(rgb[0], 0.987f, 0.01f);
    EXPECT_NEAR(rgb[1], 0.991f, 0.01f);
    EXPECT_NEAR(rgb[2], 0.750f, 0.01f);
    getMagmaSrgb(128.0 / 255.0, rgb);  // published entry 128: (0.716387, 0.214982, 0.475290)
    EXPECT_NEAR(rgb[0], 0.716387f, 1e-6f);
    EXPECT_NEAR(rgb[1], 0.214982f, 1e-6f);
    EXPECT_NEAR(rgb[2], 0.475290f, 1e-6f);
    float previous = -1.0f;
    for (int i = 0; i < 256; ++i) {
        getMagmaSrgb(i / 255.0, rgb);
        const float l = luminance(srgbToLinear(rgb[0]), srgbToLinear(rgb[1]), srgbToLinear(rgb[2]));
        EXPECT_GT(l, previous) << i;  // magma's lightness rises monotonically
        previous = l;
    }
    Image map(2, 1, 1);
    map.values() = {1.0f, kNaNf};
    const Image colored = magmaColorize(map);
    EXPECT_NEAR(linearToSrgb(colored.at(0, 0, 2)), 0.7495f, 1e-3f);
    EXPECT_TRUE(std::isnan(colored.at(1, 0, 0)));
}
