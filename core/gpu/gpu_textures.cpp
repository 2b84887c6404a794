// CPU packing of scene textures (full mip chains) for the software sampler in scene.glsl.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/gpu/gpu_scene.h"
#include "core/util/error.h"

namespace gilab::vk {
namespace {

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

uint32_t wrapCode(WrapMode mode) {
    switch (mode) {
        case WrapMode::Repeat:
            return kWrapRepeat;
        case WrapMode::ClampToEdge:
            return kWrapClampToEdge;
        case WrapMode::MirroredRepeat:
            return kWrapMirroredRepeat;
    }
    return kWrapRepeat;
}

uint8_t quantize(float v) {
    return uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

}  // namespace

PackedTextures packTextures(const std::vector<Texture>& textures) {
    PackedTextures out;
    float decode[256];
    for (int i = 0; i < 256; ++i)
        decode[i] = srgbToLinear(float(i) / 255.0f);

    // Entries [0, n) are texture headers; level records follow.
    out.meta.resize(textures.size());
    for (size_t t = 0; t < textures.size(); ++t) {
        const Texture& tex = textures[t];
        if (tex.width <= 0 || tex.height <= 0 ||
            tex.rgba.size() != size_t(tex.width) * size_t(tex.height) * 4) {
            throw Error("texture '" + tex.name + "': " + std::to_string(tex.width) + "x" +
                        std::to_string(tex.height) + " with " + std::to_string(tex.rgba.size()) +
                        " bytes is not a valid RGBA8 image");
        }
        bool srgb = tex.colorSpace == ColorSpace::Srgb;
        uint32_t w = uint32_t(tex.width), h = uint32_t(tex.height);
        uint32_t levels = 1;
        while ((std::max(w, h) >> levels) > 0)
            ++levels;
        uint32_t firstLevel = uint32_t(out.meta.size());
        out.meta[t] = glm::uvec4(firstLevel, levels, srgb ? 1u : 0u,
                                 wrapCode(tex.wrapU) | (wrapCode(tex.wrapV) << 4));

        // Level 0 verbatim; the rest are 2x2 box filtered from a linear float copy.
        std::vector<float> current(size_t(w) * h * 4);
        for (size_t i = 0; i < current.size(); ++i) {
            uint8_t v = tex.rgba[i];
            current[i] = (srgb && i % 4 != 3) ? decode[v] : float(v) / 255.0f;
        }
        for (uint32_t level = 0; level < levels; ++level) {
            uint32_t lw = std::max(w >> level, 1u), lh = std::max(h >> level, 1u);
            if (level > 0) {
                uint32_t pw = std::max(w >> (level - 1), 1u), ph = std::max(h >> (level - 1), 1u);
                std::vector<float> next(size_t(lw) * lh * 4);
                for (uint32_t y = 0; y < lh; ++y) {
                    for (uint32_t x = 0; x < lw; ++x) {
                        uint32_t x0 = std::min(2 * x, pw - 1), x1 = std::min(2 * x + 1, pw - 1);
                        uint32_t y0 = std::min(2 * y, ph - 1), y1 = std::min(2 * y + 1, ph - 1);
                        for (int c = 0; c < 4; ++c) {
                            float sum = current[(size_t(y0) * pw + x0) * 4 + c] +
                                        current[(size_t(y0) * pw + x1) * 4 + c] +
                                        current[(size_t(y1) * pw + x0) * 4 + c] +
                                        current[(size_t(y1) * pw + x1) * 4 + c];
                            next[(size_t(y) * lw + x) * 4 + c] = 0.25f * sum;
                        }
                    }
                }
                current.swap(next);
            }
            size_t offset = out.texels.size();
            if (offset + size_t(lw) * lh > UINT32_MAX) {
                throw Error("scene textures exceed 2^32 texels");
            }
            out.meta.push_back(glm::uvec4(uint32_t(offset), lw, lh, 0));
            out.texels.resize(offset + size_t(lw) * lh);
            for (size_t i = 0; i < size_t(lw) * lh; ++i) {
                uint8_t rgba[4];
                if (level == 0) {
                    std::memcpy(rgba, &tex.rgba[i * 4], 4);  // exact source texels
                } else {
                    for (int c = 0; c < 4; ++c) {
                        float v = current[i * 4 + c];
                        rgba[c] = quantize((srgb && c != 3) ? linearToSrgb(v) : v);
                    }
                }
                out.texels[offset + i] = uint32_t(rgba[0]) | (uint32_t(rgba[1]) << 8) |
                                         (uint32_t(rgba[2]) << 16) | (uint32_t(rgba[3]) << 24);
            }
        }
    }
    return out;
}

}  // namespace gilab::vk
