// CPU packing of scene textures (full mip chains, core/scene/texture_mips.h) for the software
// sampler in scene.glsl.
#include <cstring>

#include "core/gpu/gpu_scene.h"
#include "core/scene/texture_mips.h"
#include "core/util/error.h"

namespace gilab::vk {
namespace {

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

/** Appends one level's texels (RGBA8 -> one uint32 each) and its record to `out`. */
void appendLevel(PackedTextures& out, int width, int height, const uint8_t* rgba) {
    const size_t offset = out.texels.size();
    const size_t count = size_t(width) * size_t(height);
    if (offset + count > UINT32_MAX) throw Error("scene textures exceed 2^32 texels");
    out.meta.push_back(glm::uvec4(uint32_t(offset), uint32_t(width), uint32_t(height), 0));
    out.texels.resize(offset + count);
    for (size_t i = 0; i < count; ++i) {
        const uint8_t* t = rgba + 4 * i;
        out.texels[offset + i] = uint32_t(t[0]) | (uint32_t(t[1]) << 8) | (uint32_t(t[2]) << 16) |
                                 (uint32_t(t[3]) << 24);
    }
}

}  // namespace

PackedTextures packTextures(const std::vector<Texture>& textures) {
    PackedTextures out;
    // Entries [0, n) are texture headers; level records follow.
    out.meta.resize(textures.size());
    for (size_t t = 0; t < textures.size(); ++t) {
        const Texture& tex = textures[t];
        const std::vector<TextureLevel> mips = buildMipLevels(tex);  // validates the texture
        const bool srgb = tex.colorSpace == ColorSpace::Srgb;
        const uint32_t levels = uint32_t(mips.size() + 1);
        out.meta[t] = glm::uvec4(uint32_t(out.meta.size()), levels, srgb ? 1u : 0u,
                                 wrapCode(tex.wrapU) | (wrapCode(tex.wrapV) << 4));
        appendLevel(out, tex.width, tex.height, tex.rgba.data());  // exact source texels
        for (const TextureLevel& level : mips)
            appendLevel(out, level.width, level.height, level.rgba.data());
    }
    return out;
}

}  // namespace gilab::vk
