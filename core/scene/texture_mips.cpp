#include "core/scene/texture_mips.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/util/error.h"

namespace gilab {
namespace {

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

uint8_t quantize(float v) {
    return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

}  // namespace

uint32_t mipLevelCount(int width, int height) {
    const uint32_t size = uint32_t(std::max(width, height));
    uint32_t levels = 1;
    while ((size >> levels) > 0)
        ++levels;
    return levels;
}

std::vector<TextureLevel> buildMipLevels(const Texture& tex) {
    if (tex.width <= 0 || tex.height <= 0 ||
        tex.rgba.size() != size_t(tex.width) * size_t(tex.height) * 4) {
        throw Error("texture '" + tex.name + "': " + std::to_string(tex.width) + "x" +
                    std::to_string(tex.height) + " with " + std::to_string(tex.rgba.size()) +
                    " bytes is not a valid RGBA8 image");
    }
    const bool srgb = tex.colorSpace == ColorSpace::Srgb;
    float decode[256];
    for (int i = 0; i < 256; ++i)
        decode[i] = srgbToLinear(float(i) / 255.0f);

    const uint32_t w = uint32_t(tex.width), h = uint32_t(tex.height);
    std::vector<float> current(size_t(w) * h * 4);
    for (size_t i = 0; i < current.size(); ++i) {
        const uint8_t v = tex.rgba[i];
        current[i] = (srgb && i % 4 != 3) ? decode[v] : float(v) / 255.0f;
    }
    std::vector<TextureLevel> levels;
    const uint32_t count = mipLevelCount(tex.width, tex.height);
    for (uint32_t level = 1; level < count; ++level) {
        const uint32_t pw = std::max(w >> (level - 1), 1u), ph = std::max(h >> (level - 1), 1u);
        const uint32_t lw = std::max(w >> level, 1u), lh = std::max(h >> level, 1u);
        std::vector<float> next(size_t(lw) * lh * 4);
        for (uint32_t y = 0; y < lh; ++y)
            for (uint32_t x = 0; x < lw; ++x) {
                const uint32_t x0 = std::min(2 * x, pw - 1), x1 = std::min(2 * x + 1, pw - 1);
                const uint32_t y0 = std::min(2 * y, ph - 1), y1 = std::min(2 * y + 1, ph - 1);
                for (int c = 0; c < 4; ++c) {
                    const float sum = current[(size_t(y0) * pw + x0) * 4 + c] +
                                      current[(size_t(y0) * pw + x1) * 4 + c] +
                                      current[(size_t(y1) * pw + x0) * 4 + c] +
                                      current[(size_t(y1) * pw + x1) * 4 + c];
                    next[(size_t(y) * lw + x) * 4 + c] = 0.25f * sum;
                }
            }
        current.swap(next);
        TextureLevel out;
        out.width = int(lw);
        out.height = int(lh);
        out.rgba.resize(size_t(lw) * lh * 4);
        for (size_t i = 0; i < out.rgba.size(); ++i) {
            const float v = current[i];
            out.rgba[i] = quantize((srgb && i % 4 != 3) ? linearToSrgb(v) : v);
        }
        levels.push_back(std::move(out));
    }
    return levels;
}

}  // namespace gilab
