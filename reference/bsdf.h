#pragma once
/**
 * The one BRDF of the project (docs/conventions.md, shaders/common/brdf.glsl), evaluated with
 * the same float formulas as the GLSL, plus importance sampling for the path tracer:
 *  - Lambertian materials (metallic == 0 && roughness == 1): cosine-weighted hemisphere.
 *  - Glossy materials: a one-sample mixture of the cosine lobe and GGX visible-normal sampling
 *    (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)) with the
 *    combined pdf, so the estimate f cos / pdf is unbiased whichever lobe was picked.
 * The BRDF has no transmission: f = 0 below the shading normal's hemisphere.
 */
#include <glm/glm.hpp>

namespace gilab::ref {

/** GLSL BRDF_MIN_ALPHA: GGX alpha = max(roughness^2, 1e-3). */
inline constexpr float kBrdfMinAlpha = 1.0e-3f;

/** brdf.glsl evalBrdf(n, l, v, ...) for unit n, l = wi (to the light), v = wo (to the viewer). */
glm::vec3 evalGltfBrdf(const glm::vec3& n, const glm::vec3& l, const glm::vec3& v,
                       const glm::vec3& albedo, float metallic, float roughness);

struct BsdfSample {
    glm::vec3 wi{0.0f};
    glm::vec3 f{0.0f};
    float pdf = 0.0f;  // solid angle, of the whole mixture
};

class Bsdf {
public:
    /** n: unit shading normal on the side of wo (docs/shared_passes.md, "Facing"). */
    Bsdf(const glm::vec3& n, const glm::vec3& albedo, float metallic, float roughness);

    bool isGlossy() const { return m_glossy; }
    const glm::vec3& normal() const { return m_n; }

    glm::vec3 eval(const glm::vec3& wo, const glm::vec3& wi) const {
        return evalGltfBrdf(m_n, wi, wo, m_albedo, m_metallic, m_roughness);
    }
    /** Solid-angle density with which sample() returns wi (0 for directions it never makes). */
    float pdf(const glm::vec3& wo, const glm::vec3& wi) const;
    /** Draws wi from uLobe (lobe choice) and u; false if the sample is below the surface. */
    bool sample(const glm::vec3& wo, float uLobe, glm::vec2 u, BsdfSample& out) const;

    /** Probability of picking the GGX lobe for this wo (0 for Lambertian materials). */
    float specularProbability(const glm::vec3& wo) const;

private:
    float pdfGgxVisible(const glm::vec3& wo, const glm::vec3& wi) const;

    glm::vec3 m_n;
    glm::vec3 m_albedo;
    float m_metallic;
    float m_roughness;
    float m_alpha;
    bool m_glossy;
};

}  // namespace gilab::ref
