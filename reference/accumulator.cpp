// Accumulator statistics and the image-level error measures (docs/reference.md).
#include <cmath>
#include <limits>
#include <string>

#include "core/image/color.h"
#include "core/util/error.h"
#include "reference/path_tracer.h"

namespace gilab::ref {

void Accumulator::reset(int w, int h, uint32_t replicateSamples) {
    if (w < 1 || h < 1)
        throw Error("reference accumulator: invalid size " + std::to_string(w) + "x" +
                    std::to_string(h));
    width = w;
    height = h;
    samples = 0;
    nonFiniteSamples = 0;
    const size_t n = size_t(kLayerCount) * size_t(w) * size_t(h) * 3;
    sum.assign(n, 0.0);
    sumSq.assign(n, 0.0);
    replicate = replicateSamples;
    replicateSumSq.assign(replicate > 0 ? n : 0, 0.0);
    replicateOpen.assign(replicate > 0 ? n : 0, 0.0);
}

double Accumulator::mean(Layer layer, int x, int y, int c) const {
    if (samples == 0) return 0.0;
    return sum[index(layer, x, y, c)] / double(samples);
}

double Accumulator::stdError(Layer layer, int x, int y, int c) const {
    if (samples < 2) return 0.0;
    const size_t i = index(layer, x, y, c);
    const double n = double(samples);
    if (replicateErrors()) {
        // Replicate sums S_r are i.i.d. (independent scrambles): their unbiased variance over
        // the K finished ones, per sample (/ replicate), over all samples (/ n)
        const double k = double(samples / replicate);
        const double finished = sum[i] - replicateOpen[i];
        const double varS =
            std::max(0.0, (replicateSumSq[i] - finished * finished / k) / (k - 1.0));
        return std::sqrt(varS / double(replicate) / n);
    }
    const double m = sum[i] / n;
    // Unbiased sample variance from the running sums; clamped at 0 against rounding
    const double variance = std::max(0.0, (sumSq[i] - n * m * m) / (n - 1.0));
    return std::sqrt(variance / n);
}

namespace {

template <class PixelValue>
Image layerImage(const Accumulator& acc, PixelValue value) {
    Image image(acc.width, acc.height, 3);
    for (int y = 0; y < acc.height; ++y)
        for (int x = 0; x < acc.width; ++x)
            for (int c = 0; c < 3; ++c)
                image.at(x, y, c) = float(value(x, y, c));
    return image;
}

}  // namespace

Image meanImage(const Accumulator& acc, Layer layer) {
    return layerImage(acc, [&](int x, int y, int c) { return acc.mean(layer, x, y, c); });
}

Image stdErrorImage(const Accumulator& acc, Layer layer) {
    return layerImage(acc, [&](int x, int y, int c) { return acc.stdError(layer, x, y, c); });
}

std::vector<ImageLayer> meanLayers(const Accumulator& acc) {
    std::vector<ImageLayer> out;
    for (int l = 0; l < kLayerCount; ++l)
        out.push_back({layerName(Layer(l)), meanImage(acc, Layer(l))});
    return out;
}

std::vector<ImageLayer> stdErrorLayers(const Accumulator& acc) {
    std::vector<ImageLayer> out;
    for (int l = 0; l < kLayerCount; ++l)
        out.push_back({std::string(layerName(Layer(l))) + "_stderr", stdErrorImage(acc, Layer(l))});
    return out;
}

double meanRelativeStdError(const Accumulator& acc, Layer layer) {
    if (acc.samples < 2) return std::numeric_limits<double>::infinity();
    const size_t pixels = size_t(acc.width) * size_t(acc.height);
    std::vector<double> lum(pixels), err(pixels);
    double lumSum = 0.0;
    for (int y = 0; y < acc.height; ++y) {
        for (int x = 0; x < acc.width; ++x) {
            const size_t p = size_t(y) * size_t(acc.width) + size_t(x);
            double m = 0.0, e = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double wgt = c == 0 ? kLuminanceR : c == 1 ? kLuminanceG : kLuminanceB;
                m += wgt * acc.mean(layer, x, y, c);
                // sd(sum w_c X_c) <= sum w_c sd(X_c): an upper bound without the covariances
                e += wgt * acc.stdError(layer, x, y, c);
            }
            lum[p] = m;
            err[p] = e;
            lumSum += m;
        }
    }
    const double eps = 1e-3 * lumSum / double(pixels);
    double relSum = 0.0;
    size_t counted = 0;
    for (size_t p = 0; p < pixels; ++p) {
        if (!(lum[p] > eps)) continue;
        relSum += err[p] / std::max(lum[p], eps);
        ++counted;
    }
    return counted > 0 ? relSum / double(counted) : 0.0;
}

double relativeMse(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels())
        throw Error("relativeMse: images differ in size (" + std::to_string(a.width()) + "x" +
                    std::to_string(a.height()) + "x" + std::to_string(a.channels()) + " vs " +
                    std::to_string(b.width()) + "x" + std::to_string(b.height()) + "x" +
                    std::to_string(b.channels()) + ")");
    if (a.empty()) return 0.0;
    double total = 0.0;
    const std::vector<float>& va = a.values();
    const std::vector<float>& vb = b.values();
    for (size_t i = 0; i < va.size(); ++i) {
        const double d = double(va[i]) - double(vb[i]);
        total += d * d / (double(vb[i]) * double(vb[i]) + 1e-2);
    }
    return total / double(va.size());
}

}  // namespace gilab::ref
