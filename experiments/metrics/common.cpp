// Input checks, the finite-pair substitution, separable convolution and the noise RNG.
#include <algorithm>
#include <cmath>
#include <string>

#include "core/util/error.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics::detail {

void checkPair(const Image& test, const Image& reference, const char* what) {
    auto channelsOk = [](const Image& im) { return im.channels() == 3 || im.channels() == 4; };
    if (test.empty() || reference.empty()) {
        throw Error(std::string(what) + ": empty image");
    }
    if (!channelsOk(test) || !channelsOk(reference)) {
        throw Error(std::string(what) + ": expected RGB or RGBA images, got " +
                    std::to_string(test.channels()) + " and " +
                    std::to_string(reference.channels()) + " channels");
    }
    if (test.width() != reference.width() || test.height() != reference.height()) {
        throw Error(std::string(what) + ": size mismatch, test " + std::to_string(test.width()) +
                    "x" + std::to_string(test.height()) + " vs reference " +
                    std::to_string(reference.width()) + "x" + std::to_string(reference.height()));
    }
}

void checkMask(const Mask* mask, int width, int height, const char* what) {
    if (mask == nullptr) return;
    if (mask->width() != width || mask->height() != height) {
        throw Error(std::string(what) + ": mask is " + std::to_string(mask->width()) + "x" +
                    std::to_string(mask->height()) + ", image is " + std::to_string(width) + "x" +
                    std::to_string(height));
    }
}

bool isFinitePixel(const Image& image, size_t p) {
    const float* px = image.data() + p * size_t(image.channels());
    return std::isfinite(px[0]) && std::isfinite(px[1]) && std::isfinite(px[2]);
}

void makeFinitePair(const Image& test, const Image& reference, Image& testOut, Image& refOut) {
    const int w = test.width(), h = test.height();
    testOut = Image(w, h, 3);
    refOut = Image(w, h, 3);
    const size_t tc = size_t(test.channels()), rc = size_t(reference.channels());
    for (size_t p = 0; p < test.pixelCount(); ++p) {
        const float* t = test.data() + p * tc;
        const float* r = reference.data() + p * rc;
        float* to = testOut.data() + p * 3;
        float* ro = refOut.data() + p * 3;
        const bool tFinite = isFinitePixel(test, p);
        const bool rFinite = isFinitePixel(reference, p);
        for (int c = 0; c < 3; ++c) {
            const float rv = rFinite ? r[c] : 0.0f;
            ro[c] = rv;
            to[c] = (tFinite && rFinite) ? t[c] : rv;
        }
    }
}

void convolveRows(const Plane& src, Plane& dst, const std::vector<float>& kernel) {
    const int w = src.width, h = src.height;
    const int r = int(kernel.size() / 2);
    dst = Plane(w, h);
    std::vector<float> padded(size_t(w + 2 * r));
    for (int y = 0; y < h; ++y) {
        const float* row = src.v.data() + size_t(y) * size_t(w);
        for (int i = 0; i < w + 2 * r; ++i)
            padded[size_t(i)] = row[std::clamp(i - r, 0, w - 1)];
        float* out = dst.v.data() + size_t(y) * size_t(w);
        // Tap-outer order so the inner loop is a contiguous multiply-add (vectorises).
        for (size_t t = 0; t < kernel.size(); ++t) {
            const float k = kernel[t];
            const float* in = padded.data() + t;
            for (int x = 0; x < w; ++x)
                out[x] += k * in[x];
        }
    }
}

void convolveCols(const Plane& src, Plane& dst, const std::vector<float>& kernel) {
    const int w = src.width, h = src.height;
    const int r = int(kernel.size() / 2);
    dst = Plane(w, h);
    for (int y = 0; y < h; ++y) {
        float* out = dst.v.data() + size_t(y) * size_t(w);
        for (size_t t = 0; t < kernel.size(); ++t) {
            const int sy = std::clamp(y + int(t) - r, 0, h - 1);
            const float k = kernel[t];
            const float* in = src.v.data() + size_t(sy) * size_t(w);
            for (int x = 0; x < w; ++x)
                out[x] += k * in[x];
        }
    }
}

Plane convolveSeparable(const Plane& src, const std::vector<float>& kx,
                        const std::vector<float>& ky) {
    Plane tmp, out;
    convolveRows(src, tmp, kx);
    convolveCols(tmp, out, ky);
    return out;
}

uint64_t NormalRng::nextU64() {
    // splitmix64 (Steele, Lea, Flood 2014): a fixed, platform-independent sequence.
    uint64_t z = (m_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

double NormalRng::next() {
    if (m_hasSpare) {
        m_hasSpare = false;
        return m_spare;
    }
    // Box–Muller: u1 in (0, 1], u2 in [0, 1).
    const double u1 = (double(nextU64() >> 11) + 1.0) * 0x1.0p-53;
    const double u2 = double(nextU64() >> 11) * 0x1.0p-53;
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * 3.14159265358979323846 * u2;
    m_spare = radius * std::sin(angle);
    m_hasSpare = true;
    return radius * std::cos(angle);
}

}  // namespace gilab::metrics::detail
