#pragma once
/** Internal: error bars from the reference's noise (error_bars.cpp), used by computeMetrics. */
#include <cstdint>
#include <functional>
#include <vector>

#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics::detail {

/** The resampled metrics of one (test, reference) pair; NaN where not computed. */
struct ResampledMetrics {
    double psnrLdr = kNaN;
    double psnrHdr = kNaN;
    double ssim = kNaN;
    double flip = kNaN;     // HDR-FLIP mean
    double flipLdr = kNaN;  // LDR-FLIP mean
};

/** r̂ + σ · N(0, 1) per channel (RGB); non-finite pixels are copied unchanged. */
Image resampleReference(const Image& ref, const Image& stdError, NormalRng& rng);

/**
 * mean σ² (MSE floor), ±1σ of the MSE, MSE − floor, and the same for relMSE with the weight
 * 1 / (r̂² + ε), over the included pixels and 3 channels.
 */
void computeAnalyticBars(const Image& test, const Image& ref, const Image& stdError,
                         const std::vector<uint8_t>& include, ErrorBars& bars, double measuredMse,
                         double measuredRelMse);

/**
 * The resampled bars from M(test, r̂_k) (evaluated by `vsTest` on the draws of noiseSeed) and
 * the noise floor M(r̂_k, r̂) of computeNoiseFloor.
 */
void computeResampledBars(
    const Image& test, const Image& ref, const Image& stdError, const MetricOptions& options,
    const std::function<ResampledMetrics(const Image& test, const Image& noisyRef)>& vsTest,
    const NoiseFloorSamples& floor, const MetricSet& measured, ErrorBars& bars);

}  // namespace gilab::metrics::detail
