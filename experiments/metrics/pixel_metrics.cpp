// Per-pixel metrics: MSE, RMSE, relMSE, PSNR (LDR and HDR) and the energy ratio.
#include <algorithm>
#include <cmath>

#include "core/image/color.h"
#include "core/util/error.h"
#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics {

namespace {

ScalarResult withCounts(const PixelSelection& sel, double value) {
    ScalarResult r;
    r.value = sel.pixels > 0 ? value : kNaN;
    r.pixels = sel.pixels;
    r.testNonFinite = sel.testNonFinite;
    r.refNonFinite = sel.refNonFinite;
    return r;
}

/** Mean over included pixels and the 3 channels of f(t, r). */
template <typename F>
double meanOverChannels(const Image& test, const Image& ref, const PixelSelection& sel, F f) {
    const size_t tc = size_t(test.channels()), rc = size_t(ref.channels());
    double sum = 0.0;
    for (size_t p = 0; p < test.pixelCount(); ++p) {
        if (!sel.include[p]) continue;
        for (size_t c = 0; c < 3; ++c) {
            sum += f(double(test.data()[p * tc + c]), double(ref.data()[p * rc + c]));
        }
    }
    return sel.pixels > 0 ? sum / (3.0 * double(sel.pixels)) : kNaN;
}

double psnrFromMse(double peak, double mse) {
    if (std::isnan(mse) || std::isnan(peak)) return kNaN;
    if (mse == 0.0) return kInf;
    return 10.0 * std::log10(peak * peak / mse);
}

}  // namespace

ScalarResult computeMse(const Image& test, const Image& reference, const Mask* mask) {
    const PixelSelection sel = selectPixels(test, reference, mask);
    return withCounts(sel, meanOverChannels(test, reference, sel,
                                            [](double t, double r) { return (t - r) * (t - r); }));
}

ScalarResult computeRmse(const Image& test, const Image& reference, const Mask* mask) {
    ScalarResult r = computeMse(test, reference, mask);
    r.value = std::sqrt(r.value);
    return r;
}

ScalarResult computeRelMse(const Image& test, const Image& reference, const Mask* mask) {
    const PixelSelection sel = selectPixels(test, reference, mask);
    // The definition of gilab::ref::relativeMse: (t − r)² / (r² + 1e-2).
    return withCounts(sel, meanOverChannels(test, reference, sel, [](double t, double r) {
                          return (t - r) * (t - r) / (r * r + kRelMseEpsilon);
                      }));
}

ScalarResult computePsnrLdr(const Image& test, const Image& reference, const ToneMap& tonemap,
                            const Mask* mask) {
    const PixelSelection sel = selectPixels(test, reference, mask);
    const Image t = tonemapToSrgb(test, tonemap);
    const Image r = tonemapToSrgb(reference, tonemap);
    // 8-bit quantisation exactly as the PNG writer does it: round(v · 255).
    const double mse = meanOverChannels(t, r, sel, [](double a, double b) {
        const double d = double(std::lround(a * 255.0) - std::lround(b * 255.0));
        return d * d;
    });
    return withCounts(sel, psnrFromMse(255.0, mse));
}

double getHdrPeak(const Image& reference) {
    double peak = -kInf;
    const size_t ch = size_t(reference.channels());
    for (size_t p = 0; p < reference.pixelCount(); ++p) {
        for (size_t c = 0; c < std::min<size_t>(ch, 3); ++c) {
            const float v = reference.data()[p * ch + c];
            if (std::isfinite(v)) peak = std::max(peak, double(v));
        }
    }
    return std::isfinite(peak) ? peak : kNaN;
}

ScalarResult computePsnrHdr(const Image& test, const Image& reference, const Mask* mask,
                            std::optional<double> peak) {
    const PixelSelection sel = selectPixels(test, reference, mask);
    const double p = peak ? *peak : getHdrPeak(reference);
    if (peak && !(*peak > 0.0)) throw Error("PSNR (HDR): the peak must be positive");
    const double mse = meanOverChannels(test, reference, sel,
                                        [](double t, double r) { return (t - r) * (t - r); });
    return withCounts(sel, p > 0.0 ? psnrFromMse(p, mse) : kNaN);
}

double computeEnergyRatio(const Image& testLayer, const Image& referenceLayer, const Mask* mask) {
    const PixelSelection sel = selectPixels(testLayer, referenceLayer, mask);
    const size_t tc = size_t(testLayer.channels()), rc = size_t(referenceLayer.channels());
    double sumT = 0.0, sumR = 0.0;
    for (size_t p = 0; p < testLayer.pixelCount(); ++p) {
        if (!sel.include[p]) continue;
        const float* t = testLayer.data() + p * tc;
        const float* r = referenceLayer.data() + p * rc;
        sumT += luminance(t[0], t[1], t[2]);
        sumR += luminance(r[0], r[1], r[2]);
    }
    // The pixel counts cancel: ratio of means = ratio of sums.
    return (sel.pixels > 0 && sumR != 0.0) ? sumT / sumR : kNaN;
}

}  // namespace gilab::metrics
