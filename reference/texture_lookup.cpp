#include "reference/texture_lookup.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/util/error.h"

namespace gilab::ref {
namespace {

/** scene.glsl sceneSrgbToLinear on an 8-bit value (unpackUnorm4x8 gives byte / 255). */
float decodeSrgb(uint8_t byte) {
    const float c = float(byte) / 255.0f;
    return c > 0.04045f ? std::pow((c + 0.055f) / 1.055f, 2.4f) : c / 12.92f;
}

/** scene.glsl sceneWrapCoord: floor modulo for repeat, reflection for mirrored repeat. */
int wrapCoord(int i, int n, WrapMode mode) {
    switch (mode) {
        case WrapMode::ClampToEdge:
            return std::clamp(i, 0, n - 1);
        case WrapMode::MirroredRepeat: {
            int m = i % (2 * n);
            if (m < 0) m += 2 * n;
            return m < n ? m : 2 * n - 1 - m;
        }
        case WrapMode::Repeat:
        default: {
            int m = i % n;
            return m < 0 ? m + n : m;
        }
    }
}

/** GLSL mix(a, b, t) = a * (1 - t) + b * t. */
glm::vec4 mixGlsl(const glm::vec4& a, const glm::vec4& b, float t) {
    return a * (1.0f - t) + b * t;
}

}  // namespace

TextureLookup::TextureLookup(const std::vector<Texture>& textures, bool mips) {
    for (int i = 0; i < 256; ++i) {
        m_srgbTable[i] = decodeSrgb(uint8_t(i));
        m_linearTable[i] = float(i) / 255.0f;
    }
    m_textures.reserve(textures.size());
    for (const Texture& t : textures) {
        if (t.width <= 0 || t.height <= 0 ||
            t.rgba.size() != size_t(t.width) * size_t(t.height) * 4) {
            throw Error("texture '" + t.name + "': " + std::to_string(t.width) + "x" +
                        std::to_string(t.height) + " with " + std::to_string(t.rgba.size()) +
                        " bytes is not a valid RGBA8 image");
        }
        Decoded d;
        d.width = t.width;
        d.height = t.height;
        d.wrapU = t.wrapU;
        d.wrapV = t.wrapV;
        d.srgb = t.colorSpace == ColorSpace::Srgb;
        d.rgba = t.rgba.data();
        glm::dvec4 sum(0.0);
        for (int y = 0; y < d.height; ++y)
            for (int x = 0; x < d.width; ++x)
                sum += glm::dvec4(fetch(d, x, y));
        d.mean = glm::vec4(sum / (double(d.width) * double(d.height)));
        d.levels.push_back({d.width, d.height, d.rgba});
        m_textures.push_back(d);
    }
    if (!mips) return;
    m_mips.reserve(textures.size());
    for (size_t i = 0; i < textures.size(); ++i) {
        m_mips.push_back(buildMipLevels(textures[i]));
        for (const TextureLevel& level : m_mips.back())
            m_textures[i].levels.push_back({level.width, level.height, level.rgba.data()});
    }
}

glm::vec4 TextureLookup::fetch(const Decoded& d, int x, int y) const {
    const uint8_t* p = d.rgba + (size_t(y) * size_t(d.width) + size_t(x)) * 4;
    const float* table = d.srgb ? m_srgbTable : m_linearTable;
    return {table[p[0]], table[p[1]], table[p[2]], m_linearTable[p[3]]};
}

void TextureLookup::prefetch(int texture, glm::vec2 uv) const {
    const Decoded& d = m_textures[size_t(texture)];
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return;
    const glm::vec2 st = glm::floor(uv * glm::vec2(float(d.width), float(d.height)) - 0.5f);
    const int x = wrapCoord(int(std::clamp(st.x, -4194304.0f, 4194304.0f)), d.width, d.wrapU);
    const int y0 = int(std::clamp(st.y, -4194304.0f, 4194304.0f));
    for (int y : {wrapCoord(y0, d.height, d.wrapV), wrapCoord(y0 + 1, d.height, d.wrapV)})
        __builtin_prefetch(d.rgba + (size_t(y) * size_t(d.width) + size_t(x)) * 4);
}

glm::vec4 TextureLookup::bilinear(const Decoded& d, const Level& level, glm::vec2 uv) const {
    if (!std::isfinite(uv.x)) uv.x = 0.0f;
    if (!std::isfinite(uv.y)) uv.y = 0.0f;
    // Texel centres at (i + 0.5) / size (scene.glsl sceneBilinear)
    const glm::vec2 st = uv * glm::vec2(float(level.width), float(level.height)) - 0.5f;
    const glm::vec2 base = glm::floor(st);
    const glm::vec2 f = st - base;
    // Far outside [0, 1] the int conversion would overflow; wrap modes make it periodic or
    // constant there, so clamping the index to +-2^22 changes nothing representable.
    const int i0 = int(std::clamp(base.x, -4194304.0f, 4194304.0f));
    const int j0 = int(std::clamp(base.y, -4194304.0f, 4194304.0f));
    const int x0 = wrapCoord(i0, level.width, d.wrapU);
    const int x1 = wrapCoord(i0 + 1, level.width, d.wrapU);
    const int y0 = wrapCoord(j0, level.height, d.wrapV);
    const int y1 = wrapCoord(j0 + 1, level.height, d.wrapV);
    const float* table = d.srgb ? m_srgbTable : m_linearTable;
    auto at = [&](int x, int y) {
        const uint8_t* p = level.rgba + (size_t(y) * size_t(level.width) + size_t(x)) * 4;
        return glm::vec4(table[p[0]], table[p[1]], table[p[2]], m_linearTable[p[3]]);
    };
    const glm::vec4 a = mixGlsl(at(x0, y0), at(x1, y0), f.x);
    const glm::vec4 b = mixGlsl(at(x0, y1), at(x1, y1), f.x);
    return mixGlsl(a, b, f.y);
}

glm::vec4 TextureLookup::sample(int texture, glm::vec2 uv) const {
    const Decoded& d = m_textures[size_t(texture)];
    return bilinear(d, d.levels[0], uv);
}

glm::vec4 TextureLookup::sample(int texture, glm::vec2 uv, const TextureFootprint& fp) const {
    const Decoded& d = m_textures[size_t(texture)];
    // scene.glsl sceneTextureLod: log2 of the larger footprint axis in level-0 texels
    const glm::vec2 size(float(d.width), float(d.height));
    const float rho = std::max(glm::length(fp.dx * size), glm::length(fp.dy * size));
    const float lod = std::log2(std::max(rho, 1e-8f));
    // sceneSampleTextureLod: linear between the two nearest levels of the chain
    const float l = std::clamp(std::isfinite(lod) ? lod : 0.0f, 0.0f, float(d.levels.size() - 1));
    const size_t l0 = size_t(std::floor(l));
    const float t = l - float(l0);
    glm::vec4 c = bilinear(d, d.levels[l0], uv);
    if (t > 0.0f) c = mixGlsl(c, bilinear(d, d.levels[l0 + 1], uv), t);
    return c;
}

namespace {
glm::vec4 sampleWith(const TextureLookup& tex, int texture, glm::vec2 uv,
                     const TextureFootprint* fp) {
    return fp ? tex.sample(texture, uv, *fp) : tex.sample(texture, uv);
}
}  // namespace

glm::vec4 lookupBaseColor(const Material& m, const TextureLookup& tex, glm::vec2 uv,
                          const TextureFootprint* fp) {
    glm::vec4 c = m.baseColorFactor;
    if (m.baseColorTexture >= 0) c *= sampleWith(tex, m.baseColorTexture, uv, fp);
    return c;
}

glm::vec3 lookupEmission(const Material& m, const TextureLookup& tex, glm::vec2 uv,
                         const TextureFootprint* fp) {
    glm::vec3 e = m.emissiveFactor;
    if (m.emissiveTexture >= 0) e *= glm::vec3(sampleWith(tex, m.emissiveTexture, uv, fp));
    return e;
}

glm::vec2 lookupMetalRough(const Material& m, const TextureLookup& tex, glm::vec2 uv,
                           const TextureFootprint* fp) {
    glm::vec2 mr(m.metallic, m.roughness);
    if (m.metallicRoughnessTexture >= 0) {
        const glm::vec4 t = sampleWith(tex, m.metallicRoughnessTexture, uv, fp);
        mr *= glm::vec2(t.b, t.g);
    }
    return mr;
}

bool isCutOut(const Material& m, const TextureLookup& tex, glm::vec2 uv) {
    if (m.alphaMode == AlphaMode::Opaque) return false;
    return lookupBaseColor(m, tex, uv).a < m.alphaCutoff;
}

}  // namespace gilab::ref
