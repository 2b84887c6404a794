#pragma once
/**
 * Light sampling of the path tracer (docs/conventions.md, "Lights").
 *
 * Punctual lights are delta lights: every vertex evaluates all of them (next-event estimation,
 * no light selection), with lights.glsl's formulas: E = I / r^2 (point), I s(w) / r^2 with the
 * glTF t^2 spot falloff (spot), E_perp (directional).
 *
 * Emissive triangles are sampled by power: triangle i is picked with probability proportional
 * to luminance(Le_i) x area_i (x 2 when double-sided) from a CDF over the emissive triangles,
 * then a point uniformly on it. Le_i is the triangle's mean radiance (meanTriangleEmission:
 * the emissive factor times the emissive texture's mean over the triangle's uv footprint),
 * floored at 1e-3 of the factor times the whole texture's mean; the texture itself is
 * evaluated at the sampled point, so the table only has to be positive wherever emission is
 * (a texture with any non-zero texel has a positive mean).
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace gilab::ref {

class EmbreeScene;
class TextureLookup;

/**
 * lights.glsl lightIrradiancePerp for a scene light: the irradiance at x on a surface facing
 * the light (before the receiver's cosine), the unit direction wi to it and its distance
 * (infinity for directional lights). Zero at the light's own position.
 */
glm::vec3 punctualIrradiance(const Light& light, float cosInner, float cosOuter, const glm::vec3& x,
                             glm::vec3& wi, float& dist);

/** lights.glsl spotAttenuation: t = saturate((cd - cos outer) / (cos inner - cos outer)), t^2. */
float spotFalloff(float cd, float cosInner, float cosOuter);

struct EmitterSample {
    uint32_t prim = 0;
    glm::vec2 bary{0.0f};  // (b1, b2)
    glm::vec3 p{0.0f};
    float pdfArea = 0.0f;  // P(triangle) / area
};

class LightSampler {
public:
    LightSampler(const Scene& scene, const TextureLookup& textures, const EmbreeScene& mesh);

    size_t punctualCount() const { return m_lights.size(); }
    /** Punctual light i with its cached cone cosines. */
    glm::vec3 punctualIrradiance(size_t i, const glm::vec3& x, glm::vec3& wi, float& dist) const;
    const Light& punctual(size_t i) const { return m_lights[i].light; }

    bool hasEmitters() const { return !m_emitters.empty(); }
    size_t emitterCount() const { return m_emitters.size(); }
    /** Total luminance power of the table (sum of luminance(Le) x area x sides). */
    double totalPower() const { return m_totalPower; }

    /** Picks a triangle by power (uSelect, 53 bits) and a uniform point on it (u). */
    bool sampleEmitter(double uSelect, glm::vec2 u, EmitterSample& out) const;
    /** Area density with which sampleEmitter returns a point of triangle `prim`. */
    float pdfArea(uint32_t prim) const { return m_pdfArea.empty() ? 0.0f : m_pdfArea[prim]; }

private:
    struct Punctual {
        Light light;
        float cosInner;
        float cosOuter;
    };
    const EmbreeScene& m_mesh;
    std::vector<Punctual> m_lights;
    std::vector<uint32_t> m_emitters;  // triangle ids with positive power
    std::vector<double> m_cdf;         // inclusive prefix sums, normalised; back() == 1
    std::vector<float> m_pdfArea;      // per triangle of the scene (0 = never sampled)
    double m_totalPower = 0.0;
};

}  // namespace gilab::ref
