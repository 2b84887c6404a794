// LDR-FLIP feature pipeline [FLIP20, "Feature pipeline"]: edges (first Gaussian derivative)
// and points (second Gaussian derivative) of the achromatic channel, sized from ppd.
#include <algorithm>
#include <cmath>

#include "experiments/metrics/flip_constants.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics::detail {

namespace {

using namespace gilab::metrics::flip;

/** Scales positive weights to sum to 1 and negative weights to sum to −1. */
void normalizeSigned(std::vector<float>& k) {
    double pos = 0.0, neg = 0.0;
    for (float v : k)
        (v > 0.0f ? pos : neg) += v;
    for (float& v : k) {
        if (v > 0.0f) v = float(v / pos);
        if (v < 0.0f) v = float(v / -neg);
    }
}

struct FeatureKernels {
    std::vector<float> gauss;   // G, sum 1
    std::vector<float> first;   // dG/dx, ±1 normalised
    std::vector<float> second;  // d²G/dx², ±1 normalised
};

FeatureKernels makeKernels(double ppd) {
    const double sigma = 0.5 * kFeatureWidthDeg * ppd;
    const int radius = int(std::ceil(kFeatureRadiusSigmas * sigma));
    FeatureKernels k;
    double sum = 0.0;
    for (int t = -radius; t <= radius; ++t) {
        const double x = double(t);
        const double g = std::exp(-x * x / (2.0 * sigma * sigma));
        k.gauss.push_back(float(g));
        k.first.push_back(float(-x * g));
        k.second.push_back(float((x * x / (sigma * sigma) - 1.0) * g));
        sum += g;
    }
    for (float& v : k.gauss)
        v = float(v / sum);
    normalizeSigned(k.first);
    normalizeSigned(k.second);
    return k;
}

/** ‖edge‖ and ‖point‖ responses of the achromatic channel Y/Yn of linear RGB planes. */
void computeFeatures(const RgbPlanes& rgb, const FeatureKernels& k, Plane& edge, Plane& point) {
    const int w = rgb.r.width, h = rgb.r.height;
    const double yn = kRgbToXyz[1][0] + kRgbToXyz[1][1] + kRgbToXyz[1][2];
    Plane y(w, h);
    for (size_t p = 0; p < y.v.size(); ++p) {
        y.v[p] = float((kRgbToXyz[1][0] * rgb.r.v[p] + kRgbToXyz[1][1] * rgb.g.v[p] +
                        kRgbToXyz[1][2] * rgb.b.v[p]) /
                       yn);
    }
    // Three row passes shared by the four 2D filters (separable: kernel(x) · kernel(y)).
    Plane rowGauss, rowFirst, rowSecond;
    convolveRows(y, rowGauss, k.gauss);
    convolveRows(y, rowFirst, k.first);
    convolveRows(y, rowSecond, k.second);
    Plane ex, ey, px, py;
    convolveCols(rowFirst, ex, k.gauss);
    convolveCols(rowGauss, ey, k.first);
    convolveCols(rowSecond, px, k.gauss);
    convolveCols(rowGauss, py, k.second);
    edge = Plane(w, h);
    point = Plane(w, h);
    for (size_t p = 0; p < y.v.size(); ++p) {
        edge.v[p] = std::sqrt(ex.v[p] * ex.v[p] + ey.v[p] * ey.v[p]);
        point.v[p] = std::sqrt(px.v[p] * px.v[p] + py.v[p] * py.v[p]);
    }
}

}  // namespace

std::vector<float> computeFeatureError(const RgbPlanes& test, const RgbPlanes& ref, double ppd) {
    const FeatureKernels kernels = makeKernels(ppd);
    Plane edgeT, pointT, edgeR, pointR;
    computeFeatures(test, kernels, edgeT, pointT);
    computeFeatures(ref, kernels, edgeR, pointR);
    std::vector<float> err(edgeT.v.size());
    const double invSqrt2 = 1.0 / std::sqrt(2.0);
    for (size_t p = 0; p < err.size(); ++p) {
        const double de = std::abs(double(edgeR.v[p]) - double(edgeT.v[p]));
        const double dp = std::abs(double(pointR.v[p]) - double(pointT.v[p]));
        const double e = std::pow(std::max(de, dp) * invSqrt2, kFeatureExponent);
        err[p] = float(std::clamp(e, 0.0, 1.0));
    }
    return err;
}

}  // namespace gilab::metrics::detail
