#include "core/image/image.h"

#include <algorithm>
#include <cmath>

#include "core/image/color.h"
#include "core/util/error.h"

namespace gilab {

Image::Image(int width, int height, int channels, float fill) {
    if (width < 0 || height < 0 || channels < 0) {
        throw Error("Image: invalid size " + std::to_string(width) + "x" + std::to_string(height) +
                    "x" + std::to_string(channels));
    }
    m_width = width;
    m_height = height;
    m_channels = channels;
    m_data.assign(size_t(width) * size_t(height) * size_t(channels), fill);
}

Image Image::channelRange(int first, int count) const {
    if (first < 0 || count < 0 || first + count > m_channels) {
        throw Error("Image::channelRange: channels [" + std::to_string(first) + ", " +
                    std::to_string(first + count) + ") outside an image with " +
                    std::to_string(m_channels) + " channels");
    }
    Image out(m_width, m_height, count);
    const size_t pixels = pixelCount();
    for (size_t p = 0; p < pixels; ++p) {
        const float* src = m_data.data() + p * size_t(m_channels) + size_t(first);
        float* dst = out.m_data.data() + p * size_t(count);
        for (int c = 0; c < count; ++c)
            dst[c] = src[c];
    }
    return out;
}

FiniteStats countNonFinite(const Image& image) {
    FiniteStats stats;
    const size_t pixels = image.pixelCount();
    const int channels = image.channels();
    const float* data = image.data();
    for (size_t p = 0; p < pixels; ++p) {
        bool nan = false;
        bool inf = false;
        bool negative = false;
        for (int c = 0; c < channels; ++c) {
            float v = data[p * size_t(channels) + size_t(c)];
            if (std::isnan(v)) {
                nan = true;
            } else if (std::isinf(v)) {
                inf = true;
            } else if (v < 0.0f) {
                negative = true;
            }
        }
        stats.nanPixels += nan ? 1 : 0;
        stats.infPixels += inf ? 1 : 0;
        stats.negativePixels += negative ? 1 : 0;
    }
    return stats;
}

double meanLuminance(const Image& rgb) {
    double sum = 0.0;
    for (int y = 0; y < rgb.height(); ++y)
        for (int x = 0; x < rgb.width(); ++x) {
            const double l = luminance(rgb.at(x, y, 0), rgb.at(x, y, 1), rgb.at(x, y, 2));
            if (std::isfinite(l)) sum += l;
        }
    const double n = double(rgb.width()) * double(rgb.height());
    return n > 0.0 ? sum / n : 0.0;
}

double maxLuminance(const Image& rgb) {
    double m = 0.0;
    for (int y = 0; y < rgb.height(); ++y)
        for (int x = 0; x < rgb.width(); ++x) {
            const double l = luminance(rgb.at(x, y, 0), rgb.at(x, y, 1), rgb.at(x, y, 2));
            if (std::isfinite(l)) m = std::max(m, l);
        }
    return m;
}

}  // namespace gilab
