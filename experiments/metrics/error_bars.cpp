// Error bars from the reference's own noise (docs/metrics.md, "Error bars"): analytic for
// MSE and relMSE, by resampling the reference r̂ + N(0, σ²) for PSNR, SSIM and FLIP.
#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "experiments/metrics/error_bars.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics::detail {

namespace {

struct Summary {
    double mean = kNaN;
    double sd = kNaN;
};

/** Mean and sample std. dev. of the finite samples; all +inf gives (+inf, 0). */
Summary summarize(const std::vector<double>& samples) {
    std::vector<double> finite;
    for (double s : samples) {
        if (std::isfinite(s)) finite.push_back(s);
    }
    Summary out;
    if (finite.empty()) {
        const bool allInf = !samples.empty() && std::all_of(samples.begin(), samples.end(),
                                                            [](double s) { return s == kInf; });
        if (allInf) out = {kInf, 0.0};
        return out;
    }
    double sum = 0.0;
    for (double s : finite)
        sum += s;
    out.mean = sum / double(finite.size());
    double sq = 0.0;
    for (double s : finite)
        sq += (s - out.mean) * (s - out.mean);
    out.sd = finite.size() > 1 ? std::sqrt(sq / double(finite.size() - 1)) : 0.0;
    return out;
}

/** spread of M(test, r̂_k); floor from M(r̂_k, r̂); the within-noise rule (2 floor spreads). */
ResampledBar makeBar(double measured, const std::vector<double>& vsTest,
                     const std::vector<double>& vsFloor, bool higherIsBetter) {
    ResampledBar bar;
    if (vsTest.empty()) return bar;
    bar.spread = summarize(vsTest).sd;
    const Summary floor = summarize(vsFloor);
    bar.floorMean = floor.mean;
    bar.floorSpread = floor.sd;
    if (std::isnan(measured) || std::isnan(floor.mean)) return bar;
    const double slack = 2.0 * (std::isfinite(floor.sd) ? floor.sd : 0.0);
    bar.withinNoise =
        higherIsBetter ? measured >= floor.mean - slack : measured <= floor.mean + slack;
    return bar;
}

}  // namespace

Image resampleReference(const Image& ref, const Image& stdError, NormalRng& rng) {
    Image out(ref.width(), ref.height(), 3);
    const size_t rc = size_t(ref.channels()), sc = size_t(stdError.channels());
    for (size_t p = 0; p < ref.pixelCount(); ++p) {
        for (size_t c = 0; c < 3; ++c) {
            const float r = ref.data()[p * rc + c];
            const float s = stdError.data()[p * sc + c];
            const double noise = rng.next();  // drawn for every value: a fixed stream
            out.data()[p * 3 + c] =
                (std::isfinite(r) && std::isfinite(s)) ? float(r + s * noise) : r;
        }
    }
    return out;
}

void computeAnalyticBars(const Image& test, const Image& ref, const Image& stdError,
                         const std::vector<uint8_t>& include, ErrorBars& bars, double measuredMse,
                         double measuredRelMse) {
    const size_t tc = size_t(test.channels()), rc = size_t(ref.channels()),
                 sc = size_t(stdError.channels());
    double floorMse = 0.0, varMse = 0.0, floorRel = 0.0, varRel = 0.0;
    size_t values = 0;
    for (size_t p = 0; p < test.pixelCount(); ++p) {
        if (!include[p]) continue;
        for (size_t c = 0; c < 3; ++c) {
            const double t = test.data()[p * tc + c], r = ref.data()[p * rc + c];
            const double s2 = double(stdError.data()[p * sc + c]) * stdError.data()[p * sc + c];
            // E[(t − r̂)²] = d² + σ²: estimate d² from the measurement, at least 0.
            const double d2 = std::max((t - r) * (t - r) - s2, 0.0);
            // Var[(d − e)²] for e ~ N(0, σ²) is 4 d² σ² + 2 σ⁴.
            const double var = 4.0 * d2 * s2 + 2.0 * s2 * s2;
            const double w = 1.0 / (r * r + kRelMseEpsilon);  // relMSE weight, held fixed
            floorMse += s2;
            varMse += var;
            floorRel += w * s2;
            varRel += w * w * var;
            ++values;
        }
    }
    if (values == 0) return;
    const double k = double(values);
    bars.mseNoiseFloor = floorMse / k;
    bars.mseSigma = std::sqrt(varMse) / k;
    bars.mseDebiased = measuredMse - bars.mseNoiseFloor;
    bars.relMseNoiseFloor = floorRel / k;
    bars.relMseSigma = std::sqrt(varRel) / k;
    bars.relMseDebiased = measuredRelMse - bars.relMseNoiseFloor;
}

void computeResampledBars(
    const Image& test, const Image& ref, const Image& stdError, const MetricOptions& options,
    const std::function<ResampledMetrics(const Image& test, const Image& noisyRef)>& vsTest,
    const NoiseFloorSamples& floor, const MetricSet& measured, ErrorBars& bars) {
    const int n = options.noiseResamples;
    const std::vector<double>* f[5] = {&floor.psnrLdr, &floor.psnrHdr, &floor.ssim, &floor.flip,
                                       &floor.flipLdr};
    for (const std::vector<double>* samples : f) {
        if (samples->size() != size_t(n)) {
            throw Error("error bars: the noise floor has " + std::to_string(samples->size()) +
                        " samples, noiseResamples is " + std::to_string(n));
        }
    }
    // The same draws r̂_k as computeNoiseFloor: the same seed, in the same order.
    NormalRng rng(options.noiseSeed);
    std::vector<double> t[5];  // psnrLdr, psnrHdr, ssim, flip, flipLdr
    for (int k = 0; k < n; ++k) {
        const ResampledMetrics m = vsTest(test, resampleReference(ref, stdError, rng));
        const double a[5] = {m.psnrLdr, m.psnrHdr, m.ssim, m.flip, m.flipLdr};
        for (int i = 0; i < 5; ++i)
            t[i].push_back(a[i]);
    }
    bars.resamples = n;
    bars.psnrLdr = makeBar(measured.psnrLdr, t[0], *f[0], true);
    bars.psnrHdr = makeBar(measured.psnrHdr, t[1], *f[1], true);
    bars.ssim = makeBar(measured.ssim, t[2], *f[2], true);
    if (options.resampleFlip) {
        bars.flip = makeBar(measured.flip.mean, t[3], *f[3], false);
        bars.flipLdr = makeBar(measured.flipLdr.mean, t[4], *f[4], false);
    }
}

}  // namespace gilab::metrics::detail
