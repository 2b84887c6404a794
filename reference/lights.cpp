#include "reference/lights.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/image/color.h"
#include "core/scene/emission.h"
#include "core/util/error.h"
#include "reference/embree_scene.h"
#include "reference/sampling.h"
#include "reference/texture_lookup.h"

namespace gilab::ref {

float spotFalloff(float cd, float cosInner, float cosOuter) {
    if (cosInner - cosOuter <= 0.0f) return cd > cosOuter ? 1.0f : 0.0f;  // hard edge
    const float t = std::clamp((cd - cosOuter) / (cosInner - cosOuter), 0.0f, 1.0f);
    return t * t;
}

glm::vec3 punctualIrradiance(const Light& light, float cosInner, float cosOuter, const glm::vec3& x,
                             glm::vec3& wi, float& dist) {
    if (light.type == LightType::Directional) {
        wi = -light.direction;
        dist = std::numeric_limits<float>::infinity();
        return light.intensity;
    }
    const glm::vec3 d = light.position - x;
    const float r2 = glm::dot(d, d);
    if (r2 <= 0.0f) {
        wi = glm::vec3(0.0f, 1.0f, 0.0f);
        dist = 0.0f;
        return glm::vec3(0.0f);
    }
    dist = std::sqrt(r2);
    wi = d / dist;
    glm::vec3 e = light.intensity / r2;
    if (light.type == LightType::Spot)
        e *= spotFalloff(glm::dot(light.direction, -wi), cosInner, cosOuter);
    return e;
}

LightSampler::LightSampler(const Scene& scene, const TextureLookup& textures,
                           const EmbreeScene& mesh)
    : m_mesh(mesh) {
    for (const Light& l : scene.lights) {
        Light light = l;
        if (light.type != LightType::Point) {
            const float len = glm::length(light.direction);
            if (!(len > 0.0f) || !std::isfinite(len))
                throw Error("light '" + l.name + "' has no valid direction");
            light.direction /= len;
        }
        m_lights.push_back({light, std::cos(light.innerConeRad), std::cos(light.outerConeRad)});
    }

    // Power table over the emissive triangles: Le averaged over each triangle's footprint in
    // its emissive texture, floored at 1e-3 of the texture's whole mean so that a triangle
    // whose footprint emits between the averaging points keeps a positive probability
    std::vector<double> power;
    for (uint32_t t = 0; t < uint32_t(mesh.triangleCount()); ++t) {
        const MeshTriangle& tri = mesh.triangle(t);
        const Material& m = scene.materials[tri.material];
        if (!m.isEmissive() || !(tri.area > 0.0f)) continue;
        glm::vec3 le = meanTriangleEmission(scene, t);
        if (m.emissiveTexture >= 0)
            le = glm::max(
                le, 1e-3f * m.emissiveFactor * glm::vec3(textures.average(m.emissiveTexture)));
        const double p = double(luminance(le)) * double(tri.area) * (m.doubleSided ? 2.0 : 1.0);
        if (!(p > 0.0)) continue;
        if (!std::isfinite(p))
            throw Error("material '" + m.name + "': emission power is not finite");
        m_emitters.push_back(t);
        power.push_back(p);
    }
    if (m_emitters.empty()) return;
    m_cdf.resize(power.size());
    double sum = 0.0;
    for (size_t i = 0; i < power.size(); ++i) {
        sum += power[i];
        m_cdf[i] = sum;
    }
    m_totalPower = sum;
    for (double& c : m_cdf)
        c /= sum;
    m_cdf.back() = 1.0;
    m_pdfArea.assign(mesh.triangleCount(), 0.0f);
    for (size_t i = 0; i < m_emitters.size(); ++i)
        m_pdfArea[m_emitters[i]] =
            float(power[i] / sum / double(mesh.triangle(m_emitters[i]).area));
}

glm::vec3 LightSampler::punctualIrradiance(size_t i, const glm::vec3& x, glm::vec3& wi,
                                           float& dist) const {
    const Punctual& p = m_lights[i];
    return ref::punctualIrradiance(p.light, p.cosInner, p.cosOuter, x, wi, dist);
}

bool LightSampler::sampleEmitter(double uSelect, glm::vec2 u, EmitterSample& out) const {
    if (m_emitters.empty()) return false;
    const size_t i = size_t(std::upper_bound(m_cdf.begin(), m_cdf.end(), uSelect) - m_cdf.begin());
    const uint32_t prim = m_emitters[std::min(i, m_emitters.size() - 1)];
    const MeshTriangle& tri = m_mesh.triangle(prim);
    out.prim = prim;
    out.bary = sampleUniformTriangle(u);
    out.p = tri.p0 + out.bary.x * tri.e1() + out.bary.y * tri.e2();
    out.pdfArea = m_pdfArea[prim];
    return out.pdfArea > 0.0f;
}

}  // namespace gilab::ref
