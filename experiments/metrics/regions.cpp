// Region masks: rectangles, mask images and the "indirect-dominated pixels" region.
#include <algorithm>
#include <cmath>

#include "core/image/color.h"
#include "core/util/error.h"
#include "experiments/metrics/metrics.h"
#include "experiments/metrics/metrics_internal.h"

namespace gilab::metrics {

Mask::Mask(int width, int height, bool value) : m_width(width), m_height(height) {
    if (width <= 0 || height <= 0) {
        throw Error("Mask: invalid size " + std::to_string(width) + "x" + std::to_string(height));
    }
    m_data.assign(size_t(width) * size_t(height), value ? 1 : 0);
}

Mask Mask::fromRects(int width, int height, const std::vector<PixelRect>& rects) {
    Mask mask(width, height, false);
    for (const PixelRect& r : rects) {
        if (r.width < 0 || r.height < 0) throw Error("Mask: negative rectangle size");
        const int x0 = std::clamp(r.x, 0, width), x1 = std::clamp(r.x + r.width, 0, width);
        const int y0 = std::clamp(r.y, 0, height), y1 = std::clamp(r.y + r.height, 0, height);
        for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x)
                mask.set(x, y, true);
        }
    }
    return mask;
}

Mask Mask::fromNormalizedRects(int width, int height, const std::vector<NormalizedRect>& rects) {
    Mask mask(width, height, false);
    for (const NormalizedRect& r : rects) {
        if (!(r.x0 <= r.x1) || !(r.y0 <= r.y1)) {
            throw Error("Mask: normalised rectangle needs x0 <= x1 and y0 <= y1");
        }
        // Pixel centres (x + ½) / W inside [x0, x1).
        for (int y = 0; y < height; ++y) {
            const double cy = (y + 0.5) / height;
            if (cy < r.y0 || cy >= r.y1) continue;
            for (int x = 0; x < width; ++x) {
                const double cx = (x + 0.5) / width;
                if (cx >= r.x0 && cx < r.x1) mask.set(x, y, true);
            }
        }
    }
    return mask;
}

Mask Mask::fromImage(const Image& image, float threshold) {
    if (image.empty()) throw Error("Mask::fromImage: empty image");
    Mask mask(image.width(), image.height(), false);
    for (size_t p = 0; p < image.pixelCount(); ++p) {
        const float v = image.data()[p * size_t(image.channels())];
        mask.m_data[p] = (v > threshold) ? 1 : 0;  // NaN compares false: outside
    }
    return mask;
}

Mask Mask::fromIndirectFraction(const Image& refIndirect, const Image& refFull, double percent) {
    detail::checkPair(refIndirect, refFull, "Mask::fromIndirectFraction");
    if (!(percent >= 0.0 && percent <= 100.0)) {
        throw Error("Mask::fromIndirectFraction: percent must be in [0, 100], got " +
                    std::to_string(percent));
    }
    Mask mask(refFull.width(), refFull.height(), false);
    const size_t ci = size_t(refIndirect.channels()), cf = size_t(refFull.channels());
    for (size_t p = 0; p < refFull.pixelCount(); ++p) {
        if (!detail::isFinitePixel(refIndirect, p) || !detail::isFinitePixel(refFull, p)) continue;
        const float* ind = refIndirect.data() + p * ci;
        const float* full = refFull.data() + p * cf;
        const double yi = luminance(ind[0], ind[1], ind[2]);
        const double yf = luminance(full[0], full[1], full[2]);
        if (yf > 0.0 && yi > percent / 100.0 * yf) mask.m_data[p] = 1;
    }
    return mask;
}

size_t Mask::count() const {
    return size_t(std::count(m_data.begin(), m_data.end(), uint8_t(1)));
}

Mask Mask::inverted() const {
    Mask out = *this;
    for (uint8_t& v : out.m_data)
        v = v ? 0 : 1;
    return out;
}

Mask Mask::intersected(const Mask& other) const {
    if (other.m_width != m_width || other.m_height != m_height) {
        throw Error("Mask::intersected: size mismatch");
    }
    Mask out = *this;
    for (size_t i = 0; i < m_data.size(); ++i)
        out.m_data[i] = m_data[i] & other.m_data[i];
    return out;
}

PixelSelection selectPixels(const Image& test, const Image& reference, const Mask* mask,
                            const Image* referenceStdError) {
    detail::checkPair(test, reference, "selectPixels");
    detail::checkMask(mask, test.width(), test.height(), "selectPixels");
    if (referenceStdError) detail::checkPair(test, *referenceStdError, "reference stderr");
    PixelSelection sel;
    sel.include.assign(test.pixelCount(), 0);
    for (size_t p = 0; p < test.pixelCount(); ++p) {
        if (mask && mask->values()[p] == 0) continue;
        ++sel.regionPixels;
        const bool testOk = detail::isFinitePixel(test, p);
        const bool refOk = detail::isFinitePixel(reference, p) &&
                           (!referenceStdError || detail::isFinitePixel(*referenceStdError, p));
        if (!testOk) ++sel.testNonFinite;
        if (!refOk) ++sel.refNonFinite;
        if (testOk && refOk) {
            sel.include[p] = 1;
            ++sel.pixels;
        }
    }
    return sel;
}

}  // namespace gilab::metrics
