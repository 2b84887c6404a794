#pragma once
/**
 * A texture's mip chain, one definition for the rasteriser's software sampler (packed by
 * core/gpu/gpu_textures.cpp for shaders/common/scene.glsl) and the path tracer's primary-hit
 * lookups (reference/texture_lookup.cpp), so both filter with the same texels.
 *
 * Level l has max(width >> l, 1) x max(height >> l, 1) texels; there are
 * floor(log2(max(width, height))) + 1 levels. Level 0 is the texture itself; each further level
 * is the 2x2 box filter of the previous one in linear float (sRGB decoded first, alpha linear),
 * rounded to 8 bits (sRGB re-encoded) only when stored: the filtering never sees rounded values.
 */
#include <cstdint>
#include <vector>

#include "core/scene/scene.h"

namespace gilab {

struct TextureLevel {
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgba;  // width * height * 4, as stored (sRGB encoded if the texture is)
};

/** Number of levels of the chain, level 0 included. */
uint32_t mipLevelCount(int width, int height);

/** Levels 1.. of the chain (level 0 is `tex.rgba`); throws gilab::Error on a malformed texture. */
std::vector<TextureLevel> buildMipLevels(const Texture& tex);

}  // namespace gilab
