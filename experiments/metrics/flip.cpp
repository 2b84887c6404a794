// LDR-FLIP [FLIP20] and HDR-FLIP [FLIP21]: the per-pixel combination, the exposure range,
// the per-exposure maximum and the pooling. Constants: flip_constants.h.
#include <algorithm>
#include <cmath>
#include <exception>
#include <thread>

#include "core/image/color.h"
#include "core/util/error.h"
#include "experiments/metrics/flip_constants.h"
#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics {

namespace {

using namespace gilab::metrics::flip;

void checkPpd(double ppd, const char* what) {
    if (!(ppd > 0.0) || !std::isfinite(ppd)) {
        throw Error(std::string(what) + ": pixels per degree must be positive, got " +
                    std::to_string(ppd));
    }
}

/** Rec.709 luminance (XYZ's Y) of the finite pixels, negative values as 0. */
std::vector<double> finiteLuminances(const Image& image) {
    std::vector<double> lum;
    lum.reserve(image.pixelCount());
    for (size_t p = 0; p < image.pixelCount(); ++p) {
        if (!detail::isFinitePixel(image, p)) continue;
        const float* px = image.data() + p * size_t(image.channels());
        const double y =
            kRgbToXyz[1][0] * px[0] + kRgbToXyz[1][1] * px[1] + kRgbToXyz[1][2] * px[2];
        lum.push_back(std::max(y, 0.0));
    }
    return lum;
}

/** Median: the middle value, or the mean of the two middle values. */
double medianOf(std::vector<double> values) {
    if (values.empty()) return 0.0;
    const size_t mid = values.size() / 2;
    std::nth_element(values.begin(), values.begin() + long(mid), values.end());
    const double upper = values[mid];
    if (values.size() % 2 == 1) return upper;
    const double lower = *std::max_element(values.begin(), values.begin() + long(mid));
    return 0.5 * (lower + upper);
}

Image mapToImage(const std::vector<float>& map, int w, int h) {
    Image out(w, h, 1);
    std::copy(map.begin(), map.end(), out.values().begin());
    return out;
}

/** NaN where either input was non-finite, then pooled over the selection. */
FlipResult finishFlip(std::vector<float> map, const Image& test, const Image& ref,
                      const PixelSelection& sel) {
    for (size_t p = 0; p < map.size(); ++p) {
        if (!detail::isFinitePixel(test, p) || !detail::isFinitePixel(ref, p)) {
            map[p] = std::numeric_limits<float>::quiet_NaN();
        }
    }
    FlipResult result;
    result.errorMap = mapToImage(map, test.width(), test.height());
    result.stats = poolFlip(result.errorMap, &sel.include);
    result.testNonFinite = sel.testNonFinite;
    result.refNonFinite = sel.refNonFinite;
    return result;
}

}  // namespace

namespace detail {

RgbPlanes toPlanesSrgbDecoded(const Image& srgb01) {
    const int w = srgb01.width(), h = srgb01.height();
    RgbPlanes out{Plane(w, h), Plane(w, h), Plane(w, h)};
    Plane* planes[3] = {&out.r, &out.g, &out.b};
    const size_t ch = size_t(srgb01.channels());
    for (size_t p = 0; p < srgb01.pixelCount(); ++p) {
        for (int c = 0; c < 3; ++c) {
            const float v = srgb01.data()[p * ch + size_t(c)];
            planes[c]->v[p] = srgbToLinear(std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f);
        }
    }
    return out;
}

RgbPlanes toPlanesHdrToneMapped(const Image& linear, double exposureScale) {
    const int w = linear.width(), h = linear.height();
    RgbPlanes out{Plane(w, h), Plane(w, h), Plane(w, h)};
    Plane* planes[3] = {&out.r, &out.g, &out.b};
    const size_t ch = size_t(linear.channels());
    for (size_t p = 0; p < linear.pixelCount(); ++p) {
        for (int c = 0; c < 3; ++c) {
            const double v = std::max(double(linear.data()[p * ch + size_t(c)]), 0.0);
            planes[c]->v[p] = float(std::clamp(hdrFlipToneMap(v * exposureScale), 0.0, 1.0));
        }
    }
    return out;
}

std::vector<float> computeLdrFlipMap(const RgbPlanes& test, const RgbPlanes& ref, double ppd) {
    const HuntLab labT = computeFilteredHuntLab(test, ppd);
    const HuntLab labR = computeFilteredHuntLab(ref, ppd);
    std::vector<float> color = computeColorError(labT, labR);
    const std::vector<float> feature = computeFeatureError(test, ref, ppd);
    // [FLIP20] final error: ΔE = ΔE_c^(1 − ΔE_f).
    for (size_t p = 0; p < color.size(); ++p) {
        color[p] = float(std::pow(double(color[p]), 1.0 - double(feature[p])));
    }
    return color;
}

}  // namespace detail

double hdrFlipToneMap(double x) {
    return (kAcesA * x * x + kAcesB * x) / (kAcesC * x * x + kAcesD * x + kAcesE);
}

double hdrFlipToneMapInverse(double y) {
    // Solve (A − yC) x² + (B − yD) x − yE = 0 for its non-negative root.
    const double qa = kAcesA - y * kAcesC, qb = kAcesB - y * kAcesD, qc = -y * kAcesE;
    if (y <= 0.0) return 0.0;
    if (qa <= 0.0) return kInf;  // y at or above the curve's asymptote A/C
    return (-qb + std::sqrt(qb * qb - 4.0 * qa * qc)) / (2.0 * qa);
}

HdrExposures computeHdrExposures(const Image& refLinear, const HdrFlipOptions& options) {
    HdrExposures ex;
    if (!options.startExposure || !options.stopExposure) {
        const std::vector<double> lum = finiteLuminances(refLinear);
        const double ymax = lum.empty() ? 0.0 : *std::max_element(lum.begin(), lum.end());
        double ymedian = medianOf(lum);
        if (!(ymedian > 0.0)) {
            // Deviation: a median of 0 (mostly black image) has no stop exposure; use the
            // median of the positive luminances instead (docs/metrics.md).
            std::vector<double> positive;
            for (double v : lum) {
                if (v > 0.0) positive.push_back(v);
            }
            ymedian = medianOf(positive);
        }
        const double target = hdrFlipToneMapInverse(kExposureTarget);
        ex.start = ymax > 0.0 ? std::log2(target / ymax) : 0.0;
        ex.stop = ymedian > 0.0 ? std::log2(target / ymedian) : ex.start;
    }
    if (options.startExposure) ex.start = *options.startExposure;
    if (options.stopExposure) ex.stop = *options.stopExposure;
    ex.count = options.exposureCount
                   ? *options.exposureCount
                   : std::max(kMinExposureCount, int(std::ceil(ex.stop - ex.start)));
    if (ex.count < 1) throw Error("HDR-FLIP: exposure count must be at least 1");
    return ex;
}

FlipResult computeLdrFlip(const Image& testSrgb01, const Image& refSrgb01, double ppd,
                          const Mask* mask) {
    detail::checkPair(testSrgb01, refSrgb01, "LDR-FLIP");
    detail::checkMask(mask, testSrgb01.width(), testSrgb01.height(), "LDR-FLIP");
    checkPpd(ppd, "LDR-FLIP");
    const PixelSelection sel = selectPixels(testSrgb01, refSrgb01, mask);
    Image testF, refF;
    detail::makeFinitePair(testSrgb01, refSrgb01, testF, refF);
    std::vector<float> map = detail::computeLdrFlipMap(detail::toPlanesSrgbDecoded(testF),
                                                       detail::toPlanesSrgbDecoded(refF), ppd);
    return finishFlip(std::move(map), testSrgb01, refSrgb01, sel);
}

FlipResult computeHdrFlip(const Image& testLinear, const Image& refLinear,
                          const HdrFlipOptions& options, const Mask* mask) {
    detail::checkPair(testLinear, refLinear, "HDR-FLIP");
    detail::checkMask(mask, testLinear.width(), testLinear.height(), "HDR-FLIP");
    checkPpd(options.ppd, "HDR-FLIP");
    const PixelSelection sel = selectPixels(testLinear, refLinear, mask);
    const HdrExposures ex = computeHdrExposures(refLinear, options);
    Image testF, refF;
    detail::makeFinitePair(testLinear, refLinear, testF, refF);

    // [FLIP21] HDR-FLIP = per-pixel max over exposures of LDR-FLIP of the tonemapped images.
    // Exposures run in parallel; each worker keeps its own running maximum.
    const int workers =
        std::max(1, std::min(ex.count, int(std::max(1u, std::thread::hardware_concurrency()))));
    std::vector<std::vector<float>> partial(size_t(workers),
                                            std::vector<float>(testLinear.pixelCount(), 0.0f));
    auto computeExposures = [&](int worker) {
        for (int i = worker; i < ex.count; i += workers) {
            const double c =
                ex.count == 1 ? ex.start : ex.start + i * (ex.stop - ex.start) / (ex.count - 1);
            const double scale = std::exp2(c);
            const std::vector<float> map =
                detail::computeLdrFlipMap(detail::toPlanesHdrToneMapped(testF, scale),
                                          detail::toPlanesHdrToneMapped(refF, scale), options.ppd);
            std::vector<float>& acc = partial[size_t(worker)];
            for (size_t p = 0; p < map.size(); ++p) {
                acc[p] = std::max(acc[p], map[p]);
            }
        }
    };
    // Exceptions are carried out of the worker threads and rethrown here.
    std::vector<std::exception_ptr> errors(static_cast<size_t>(workers));
    auto work = [&](int worker) {
        try {
            computeExposures(worker);
        } catch (...) {
            errors[size_t(worker)] = std::current_exception();
        }
    };
    std::vector<std::thread> threads;
    for (int t = 1; t < workers; ++t) {
        threads.emplace_back(work, t);
    }
    work(0);
    for (std::thread& t : threads) {
        t.join();
    }
    for (const std::exception_ptr& e : errors) {
        if (e) std::rethrow_exception(e);
    }
    for (int t = 1; t < workers; ++t) {
        for (size_t p = 0; p < partial[0].size(); ++p) {
            partial[0][p] = std::max(partial[0][p], partial[size_t(t)][p]);
        }
    }
    FlipResult result = finishFlip(std::move(partial[0]), testLinear, refLinear, sel);
    result.startExposure = ex.start;
    result.stopExposure = ex.stop;
    result.exposureCount = ex.count;
    return result;
}

FlipStats poolFlip(const Image& errorMap, const std::vector<uint8_t>* include) {
    if (errorMap.channels() != 1) throw Error("poolFlip: expected a 1-channel error map");
    std::vector<double> v;
    v.reserve(errorMap.pixelCount());
    for (size_t p = 0; p < errorMap.pixelCount(); ++p) {
        if (include && (*include)[p] == 0) continue;
        const float e = errorMap.data()[p];
        if (std::isfinite(e)) v.push_back(e);
    }
    FlipStats s;
    s.pixels = v.size();
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    double sum = 0.0;
    for (double e : v)
        sum += e;
    s.mean = sum / double(v.size());
    s.min = v.front();
    s.max = v.back();
    // Weighted percentile: each value weighted by itself (the FLIP tool's weighted histogram);
    // the smallest value whose cumulative weight reaches p of the total.
    auto weighted = [&](double p) {
        if (!(sum > 0.0)) return 0.0;
        double cumulative = 0.0;
        for (double e : v) {
            cumulative += e;
            if (cumulative >= p * sum) return e;
        }
        return v.back();
    };
    s.weightedP25 = weighted(0.25);
    s.weightedMedian = weighted(0.50);
    s.weightedP75 = weighted(0.75);
    s.weightedP95 = weighted(0.95);
    return s;
}

}  // namespace gilab::metrics
