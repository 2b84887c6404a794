#pragma once
/**
 * CPU texture and material lookups of the path tracer, matching the GPU's software sampler
 * (shaders/common/scene.glsl): texel centres at (i + 0.5) / size, per-axis wrap (repeat, clamp
 * to edge, mirrored repeat), sRGB decoded to linear per texel *before* bilinear filtering (alpha
 * is always linear), factors multiplied after filtering. Lookups are at mip 0, or, given a
 * footprint (the uv change to the next pixel in x and y, as the rasteriser's derivatives), at
 * the rasteriser's mip level, trilinear over the same mip chain (core/scene/texture_mips.h).
 */
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/scene.h"
#include "core/scene/texture_mips.h"

namespace gilab::ref {

/** uv change from a pixel to its neighbours in x and y (the rasteriser's dFdx / dFdy). */
struct TextureFootprint {
    glm::vec2 dx{0.0f};
    glm::vec2 dy{0.0f};
};

/** Reads the Scene's textures in place: the Scene must outlive the lookup. */
class TextureLookup {
public:
    /** Keeps the 8-bit texels with a decode table per texture, and builds their mip chains when
     *  `mips` is set; throws gilab::Error on a bad texture. */
    explicit TextureLookup(const std::vector<Texture>& textures, bool mips = false);

    /** scene.glsl sceneBilinear() at mip 0: bilinear filtering of the decoded texels. */
    glm::vec4 sample(int texture, glm::vec2 uv) const;
    /** scene.glsl sceneSampleTextureGrad(): trilinear at the rasteriser's level for footprint
     *  `fp` (needs the mip chains; mip 0 without them). */
    glm::vec4 sample(int texture, glm::vec2 uv, const TextureFootprint& fp) const;
    /** Prefetches the texels sample(texture, uv) will read (a hint; no effect on results). */
    void prefetch(int texture, glm::vec2 uv) const;
    /** Mean of the decoded mip-0 texels (used to weight texture-emissive triangles). */
    glm::vec4 average(int texture) const { return m_textures[size_t(texture)].mean; }
    size_t count() const { return m_textures.size(); }

private:
    struct Level {
        int width = 0;
        int height = 0;
        const uint8_t* rgba = nullptr;  // row 0 = v = 0
    };
    struct Decoded {
        int width = 0;
        int height = 0;
        WrapMode wrapU = WrapMode::Repeat;
        WrapMode wrapV = WrapMode::Repeat;
        bool srgb = true;
        const uint8_t* rgba = nullptr;  // the Scene's texels, row 0 = v = 0
        glm::vec4 mean{0.0f};
        std::vector<Level> levels;  // 0 = the Scene's texels, then m_mips' (when built)
    };
    glm::vec4 fetch(const Decoded& d, int x, int y) const;
    glm::vec4 bilinear(const Decoded& d, const Level& level, glm::vec2 uv) const;

    std::vector<Decoded> m_textures;
    std::vector<std::vector<TextureLevel>> m_mips;
    float m_srgbTable[256];
    float m_linearTable[256];
};

/** Base colour factor x texture; a = coverage (scene.glsl sampleBaseColor; mip 0, or the
 *  rasteriser's level for footprint `fp`). */
glm::vec4 lookupBaseColor(const Material& m, const TextureLookup& tex, glm::vec2 uv,
                          const TextureFootprint* fp = nullptr);
/** Emitted radiance: emissive factor x texture rgb (scene.glsl sampleEmission). */
glm::vec3 lookupEmission(const Material& m, const TextureLookup& tex, glm::vec2 uv,
                         const TextureFootprint* fp = nullptr);
/** (metallic, perceptual roughness): factors x texture (B, G) (scene.glsl sampleMetalRough). */
glm::vec2 lookupMetalRough(const Material& m, const TextureLookup& tex, glm::vec2 uv,
                           const TextureFootprint* fp = nullptr);
/** True = the point is cut out: a Mask (or Blend) material with coverage below the cutoff. */
bool isCutOut(const Material& m, const TextureLookup& tex, glm::vec2 uv);

}  // namespace gilab::ref
