// computeMetrics: every metric of one test image against the reference, with error bars, and
// its JSON form.
#include <cmath>

#include "core/util/error.h"
#include "experiments/metrics/error_bars.h"
#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics {

namespace {

Mask maskFromInclude(const std::vector<uint8_t>& include, int width, int height) {
    Mask mask(width, height, false);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            mask.set(x, y, include[size_t(y) * size_t(width) + size_t(x)] != 0);
        }
    }
    return mask;
}

/** LDR-FLIP of the images as displayed with `tonemap` (non-finite pixels made equal first). */
FlipResult computeLdrFlipTonemapped(const Image& test, const Image& ref, const ToneMap& tonemap,
                                    double ppd, const Mask& include) {
    Image testF, refF;
    detail::makeFinitePair(test, ref, testF, refF);
    FlipResult r =
        computeLdrFlip(tonemapToSrgb(testF, tonemap), tonemapToSrgb(refF, tonemap), ppd, &include);
    for (size_t p = 0; p < test.pixelCount(); ++p) {
        if (!detail::isFinitePixel(test, p) || !detail::isFinitePixel(ref, p)) {
            r.errorMap.data()[p] = std::numeric_limits<float>::quiet_NaN();
        }
    }
    return r;
}

/** The measurement's settings (tonemap, ppd, HDR peak and exposures) for any image pair. */
struct Evaluator {
    const MetricOptions* options = nullptr;
    double peak = kNaN;
    bool peakOk = false;
    HdrFlipOptions flipOptions;

    detail::ResampledMetrics evaluate(const Image& t, const Image& r, const Mask& include) const {
        detail::ResampledMetrics rm;
        rm.psnrLdr = computePsnrLdr(t, r, options->tonemap, &include).value;
        rm.psnrHdr = peakOk ? computePsnrHdr(t, r, &include, peak).value : kNaN;
        rm.ssim = computeSsim(t, r, options->tonemap, &include).mean.value;
        if (options->resampleFlip) {
            rm.flip = computeHdrFlip(t, r, flipOptions, &include).stats.mean;
            rm.flipLdr =
                computeLdrFlipTonemapped(t, r, options->tonemap, options->ppd, include).stats.mean;
        }
        return rm;
    }
};

Evaluator makeEvaluator(const Image& reference, const MetricOptions& options) {
    if (options.hdrPeak && !(*options.hdrPeak > 0.0 && std::isfinite(*options.hdrPeak))) {
        throw Error("computeMetrics: hdrPeak must be positive and finite");
    }
    Evaluator e;
    e.options = &options;
    e.peak = options.hdrPeak ? *options.hdrPeak : getHdrPeak(reference);
    e.peakOk = e.peak > 0.0 && std::isfinite(e.peak);
    e.flipOptions.ppd = options.ppd;
    const HdrExposures ex = options.hdrExposures ? *options.hdrExposures
                                                 : computeHdrExposures(reference, e.flipOptions);
    e.flipOptions.startExposure = ex.start;
    e.flipOptions.stopExposure = ex.stop;
    e.flipOptions.exposureCount = ex.count;
    return e;
}

using detail::number;

nlohmann::ordered_json barJson(const ResampledBar& b) {
    return {{"spread", number(b.spread)},
            {"floor_mean", number(b.floorMean)},
            {"floor_spread", number(b.floorSpread)},
            {"within_noise", b.withinNoise}};
}

}  // namespace

NoiseFloorSamples computeNoiseFloor(const Image& reference, const MetricOptions& options) {
    const Image* stdError = options.referenceStdError;
    if (!stdError) throw Error("computeNoiseFloor: options.referenceStdError is not set");
    if (options.noiseResamples < 2) {
        throw Error("error bars: noiseResamples must be at least 2, got " +
                    std::to_string(options.noiseResamples));
    }
    const Mask* region = options.mask ? &*options.mask : nullptr;
    const PixelSelection sel = selectPixels(reference, reference, region, stdError);
    const Mask include = maskFromInclude(sel.include, reference.width(), reference.height());
    const Evaluator evaluator = makeEvaluator(reference, options);
    detail::NormalRng rng(options.noiseSeed);
    NoiseFloorSamples floor;
    for (int k = 0; k < options.noiseResamples; ++k) {
        const Image noisy = detail::resampleReference(reference, *stdError, rng);
        const detail::ResampledMetrics m = evaluator.evaluate(noisy, reference, include);
        floor.psnrLdr.push_back(m.psnrLdr);
        floor.psnrHdr.push_back(m.psnrHdr);
        floor.ssim.push_back(m.ssim);
        floor.flip.push_back(m.flip);
        floor.flipLdr.push_back(m.flipLdr);
    }
    return floor;
}

MetricSet computeMetrics(const Image& test, const Image& reference, const MetricOptions& options,
                         MetricMaps* maps) {
    detail::checkPair(test, reference, "computeMetrics");
    const Mask* region = options.mask ? &*options.mask : nullptr;
    detail::checkMask(region, test.width(), test.height(), "computeMetrics");
    const Image* stdError = options.referenceStdError;
    const PixelSelection sel = selectPixels(test, reference, region, stdError);
    // Every metric below pools over the same pixels: the region minus non-finite ones.
    const Mask include = maskFromInclude(sel.include, test.width(), test.height());
    const Evaluator evaluator = makeEvaluator(reference, options);

    MetricSet m;
    m.pixels = sel.pixels;
    m.regionPixels = sel.regionPixels;
    m.testNonFinite = sel.testNonFinite;
    m.refNonFinite = sel.refNonFinite;
    m.hasNonFinite = sel.hasNonFinite();

    m.mse = computeMse(test, reference, &include).value;
    m.rmse = std::sqrt(m.mse);
    m.relMse = computeRelMse(test, reference, &include).value;
    m.psnrLdr = computePsnrLdr(test, reference, options.tonemap, &include).value;
    m.psnrHdrPeak = evaluator.peak;
    m.psnrHdr =
        evaluator.peakOk ? computePsnrHdr(test, reference, &include, evaluator.peak).value : kNaN;

    const SsimResult ssim = computeSsim(test, reference, options.tonemap, &include);
    m.ssim = ssim.mean.value;

    m.flipExposures = {*evaluator.flipOptions.startExposure, *evaluator.flipOptions.stopExposure,
                       *evaluator.flipOptions.exposureCount};
    FlipResult hdrFlip = computeHdrFlip(test, reference, evaluator.flipOptions, &include);
    FlipResult ldrFlip =
        computeLdrFlipTonemapped(test, reference, options.tonemap, options.ppd, include);
    m.flip = hdrFlip.stats;
    m.flipLdr = ldrFlip.stats;
    if (maps) {
        maps->ssim = ssim.map;
        maps->flip = std::move(hdrFlip.errorMap);
        maps->flipLdr = std::move(ldrFlip.errorMap);
    }

    if (stdError) {
        m.bars.available = true;
        detail::computeAnalyticBars(test, reference, *stdError, sel.include, m.bars, m.mse,
                                    m.relMse);
        const NoiseFloorSamples floor =
            options.noiseFloor ? *options.noiseFloor : computeNoiseFloor(reference, options);
        detail::computeResampledBars(
            test, reference, *stdError, options,
            [&](const Image& t, const Image& noisy) {
                return evaluator.evaluate(t, noisy, include);
            },
            floor, m, m.bars);
        // docs/metrics.md: the MSE is not distinguishable from the reference's noise when it
        // is at most twice the floor mean(σ²) that an exact image would measure.
        m.withinReferenceNoise = m.mse <= 2.0 * m.bars.mseNoiseFloor;
    }
    return m;
}

nlohmann::ordered_json toJson(const FlipStats& s) {
    return {{"mean", number(s.mean)},
            {"weighted_median", number(s.weightedMedian)},
            {"weighted_p25", number(s.weightedP25)},
            {"weighted_p75", number(s.weightedP75)},
            {"weighted_p95", number(s.weightedP95)},
            {"min", number(s.min)},
            {"max", number(s.max)},
            {"pixels", s.pixels}};
}

nlohmann::ordered_json toJson(const MetricSet& m) {
    nlohmann::ordered_json j;
    j["pixels"] = m.pixels;
    j["region_pixels"] = m.regionPixels;
    j["test_non_finite"] = m.testNonFinite;
    j["ref_non_finite"] = m.refNonFinite;
    j["has_non_finite"] = m.hasNonFinite;
    j["mse"] = number(m.mse);
    j["rmse"] = number(m.rmse);
    j["rel_mse"] = number(m.relMse);
    j["psnr_ldr"] = number(m.psnrLdr);  // null: +inf (equal images) or no pixels
    j["psnr_hdr"] = number(m.psnrHdr);
    j["psnr_hdr_peak"] = number(m.psnrHdrPeak);
    j["ssim"] = number(m.ssim);
    nlohmann::ordered_json flip = toJson(m.flip);
    flip["start_exposure"] = number(m.flipExposures.start);
    flip["stop_exposure"] = number(m.flipExposures.stop);
    flip["exposures"] = m.flipExposures.count;
    j["flip"] = flip;
    j["flip_ldr"] = toJson(m.flipLdr);
    if (m.bars.available) {
        const ErrorBars& b = m.bars;
        j["error_bars"] = {{"resamples", b.resamples},
                           {"mse_noise_floor", number(b.mseNoiseFloor)},
                           {"mse_sigma", number(b.mseSigma)},
                           {"mse_debiased", number(b.mseDebiased)},
                           {"rel_mse_noise_floor", number(b.relMseNoiseFloor)},
                           {"rel_mse_sigma", number(b.relMseSigma)},
                           {"rel_mse_debiased", number(b.relMseDebiased)},
                           {"psnr_ldr", barJson(b.psnrLdr)},
                           {"psnr_hdr", barJson(b.psnrHdr)},
                           {"ssim", barJson(b.ssim)},
                           {"flip", barJson(b.flip)},
                           {"flip_ldr", barJson(b.flipLdr)}};
    } else {
        j["error_bars"] = nullptr;
    }
    j["within_reference_noise"] = m.withinReferenceNoise;
    return j;
}

}  // namespace gilab::metrics
