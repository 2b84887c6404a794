// SSIM: Z. Wang, A. C. Bovik, H. R. Sheikh, E. P. Simoncelli, "Image Quality Assessment: From
// Error Visibility to Structural Similarity", IEEE TIP 13(4), 2004. §III-B Eq. (13) with the
// §III-C settings: 11×11 circular-symmetric Gaussian window, σ = 1.5 (normalised to sum 1),
// K1 = 0.01, K2 = 0.03, L = 1; the mean over the windows that lie fully inside the image.
#include <cmath>

#include "core/image/color.h"
#include "core/util/error.h"
#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics {

namespace {

constexpr int kWindowRadius = 5;  // 11 × 11
constexpr double kWindowSigma = 1.5;
constexpr double kK1 = 0.01;
constexpr double kK2 = 0.03;
constexpr double kDynamicRange = 1.0;  // L

std::vector<float> ssimWindow() {
    std::vector<float> k;
    double sum = 0.0;
    for (int t = -kWindowRadius; t <= kWindowRadius; ++t) {
        const double g = std::exp(-double(t * t) / (2.0 * kWindowSigma * kWindowSigma));
        k.push_back(float(g));
        sum += g;
    }
    for (float& v : k)
        v = float(v / sum);
    return k;
}

/** Gaussian-weighted local mean of a plane (borders are cropped away afterwards). */
detail::Plane blur(const detail::Plane& p, const std::vector<float>& k) {
    return detail::convolveSeparable(p, k, k);
}

SsimResult computeSsimPlanes(const detail::Plane& x, const detail::Plane& y,
                             const PixelSelection& sel) {
    const int w = x.width, h = x.height;
    if (w < 2 * kWindowRadius + 1 || h < 2 * kWindowRadius + 1) {
        throw Error("SSIM: image is " + std::to_string(w) + "x" + std::to_string(h) +
                    ", smaller than the 11x11 window");
    }
    const std::vector<float> k = ssimWindow();
    detail::Plane xx(w, h), yy(w, h), xy(w, h);
    for (size_t p = 0; p < x.v.size(); ++p) {
        xx.v[p] = x.v[p] * x.v[p];
        yy.v[p] = y.v[p] * y.v[p];
        xy.v[p] = x.v[p] * y.v[p];
    }
    const detail::Plane mx = blur(x, k), my = blur(y, k);
    const detail::Plane mxx = blur(xx, k), myy = blur(yy, k), mxy = blur(xy, k);
    const double c1 = (kK1 * kDynamicRange) * (kK1 * kDynamicRange);
    const double c2 = (kK2 * kDynamicRange) * (kK2 * kDynamicRange);

    SsimResult result;
    const int mw = w - 2 * kWindowRadius, mh = h - 2 * kWindowRadius;
    result.map = Image(mw, mh, 1);
    double sum = 0.0;
    size_t count = 0;
    for (int j = 0; j < mh; ++j) {
        for (int i = 0; i < mw; ++i) {
            const size_t p = size_t(j + kWindowRadius) * size_t(w) + size_t(i + kWindowRadius);
            const double ux = mx.v[p], uy = my.v[p];
            const double vx = double(mxx.v[p]) - ux * ux;
            const double vy = double(myy.v[p]) - uy * uy;
            const double cxy = double(mxy.v[p]) - ux * uy;
            const double s = ((2.0 * ux * uy + c1) * (2.0 * cxy + c2)) /
                             ((ux * ux + uy * uy + c1) * (vx + vy + c2));
            result.map.at(i, j, 0) = float(s);
            if (sel.include[p]) {
                sum += s;
                ++count;
            }
        }
    }
    result.mean.value = count > 0 ? sum / double(count) : kNaN;
    result.mean.pixels = count;
    result.mean.testNonFinite = sel.testNonFinite;
    result.mean.refNonFinite = sel.refNonFinite;
    return result;
}

/** Rec.709 weights on the sRGB-encoded values (luma of the displayed image). */
detail::Plane lumaPlane(const Image& srgb) {
    detail::Plane out(srgb.width(), srgb.height());
    for (size_t p = 0; p < srgb.pixelCount(); ++p) {
        const float* px = srgb.data() + p * 3;
        out.v[p] = luminance(px[0], px[1], px[2]);
    }
    return out;
}

}  // namespace

SsimResult computeSsim(const Image& test, const Image& reference, const ToneMap& tonemap,
                       const Mask* mask) {
    const PixelSelection sel = selectPixels(test, reference, mask);
    Image testF, refF;
    detail::makeFinitePair(test, reference, testF, refF);
    return computeSsimPlanes(lumaPlane(tonemapToSrgb(testF, tonemap)),
                             lumaPlane(tonemapToSrgb(refF, tonemap)), sel);
}

SsimResult computeSsimLuma(const Image& testLuma, const Image& refLuma, const Mask* mask) {
    if (testLuma.channels() != 1 || refLuma.channels() != 1 ||
        testLuma.width() != refLuma.width() || testLuma.height() != refLuma.height()) {
        throw Error("SSIM: expected two 1-channel images of one size");
    }
    detail::checkMask(mask, testLuma.width(), testLuma.height(), "SSIM");
    PixelSelection sel;
    sel.include.assign(testLuma.pixelCount(), 0);
    detail::Plane x(testLuma.width(), testLuma.height()), y(refLuma.width(), refLuma.height());
    for (size_t p = 0; p < testLuma.pixelCount(); ++p) {
        const float t = testLuma.data()[p], r = refLuma.data()[p];
        const bool tOk = std::isfinite(t), rOk = std::isfinite(r);
        // The same finite value in both where either is non-finite, as makeFinitePair does.
        y.v[p] = rOk ? r : 0.0f;
        x.v[p] = (tOk && rOk) ? t : y.v[p];
        if (mask && mask->values()[p] == 0) continue;
        ++sel.regionPixels;
        if (!tOk) ++sel.testNonFinite;
        if (!rOk) ++sel.refNonFinite;
        if (tOk && rOk) {
            sel.include[p] = 1;
            ++sel.pixels;
        }
    }
    return computeSsimPlanes(x, y, sel);
}

}  // namespace gilab::metrics
