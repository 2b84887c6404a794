#include "core/passes/emitter_samples.h"

#include <algorithm>
#include <cmath>

#include "core/scene/emission.h"
#include "core/scene/scene.h"

namespace gilab {
namespace {

struct EmitterTriangle {
    uint32_t triangle = 0;
    glm::vec3 p0{0.0f}, p1{0.0f}, p2{0.0f};
    glm::vec2 uv0{0.0f}, uv1{0.0f}, uv2{0.0f};
    glm::vec3 normal{0.0f};
    float area = 0.0f;
    glm::vec3 meanRadiance{0.0f};  // over the triangle (its emissive texture's footprint)
    double power = 0.0;
    const Material* material = nullptr;
};

float luminance(const glm::vec3& c) {
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

glm::vec3 emittedRadiance(const Scene& scene, const Material& m, glm::vec2 uv) {
    glm::vec3 le = m.emissiveFactor;
    if (m.emissiveTexture >= 0 && size_t(m.emissiveTexture) < scene.textures.size()) {
        le *= bilinearLinear(scene.textures[size_t(m.emissiveTexture)], uv);
    }
    return le;
}

float radicalInverse2(uint32_t i) {
    i = (i << 16u) | (i >> 16u);
    i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
    i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
    i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
    i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
    return float(i) * 2.3283064365386963e-10f;
}

std::vector<EmitterTriangle> collectEmitters(const Scene& scene) {
    std::vector<EmitterTriangle> out;
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
        const Material& m = scene.materials[scene.triangleMaterials[t]];
        if (!m.isEmissive()) continue;
        EmitterTriangle e;
        e.triangle = uint32_t(t);
        const Vertex& v0 = scene.vertices[scene.indices[3 * t]];
        const Vertex& v1 = scene.vertices[scene.indices[3 * t + 1]];
        const Vertex& v2 = scene.vertices[scene.indices[3 * t + 2]];
        e.p0 = v0.position, e.p1 = v1.position, e.p2 = v2.position;
        e.uv0 = v0.uv, e.uv1 = v1.uv, e.uv2 = v2.uv;
        glm::vec3 c = glm::cross(e.p1 - e.p0, e.p2 - e.p0);
        float len = glm::length(c);
        if (!(len > 0.0f)) continue;
        e.normal = c / len;
        e.area = 0.5f * len;
        e.material = &m;
        e.meanRadiance = meanTriangleEmission(scene, t);
        e.power = double(luminance(e.meanRadiance)) * e.area * (m.doubleSided ? 2.0 : 1.0);
        if (e.power > 0.0) out.push_back(e);
    }
    return out;
}

}  // namespace

size_t countEmitterTriangles(const Scene& scene) {
    return collectEmitters(scene).size();
}

std::vector<EmitterPolygon> buildEmitterPolygons(const Scene& scene) {
    std::vector<EmitterPolygon> out;
    for (const EmitterTriangle& e : collectEmitters(scene)) {
        EmitterPolygon p;
        p.p0 = e.p0, p.p1 = e.p1, p.p2 = e.p2;
        p.twoSided = e.material->doubleSided;
        p.radiance = e.meanRadiance;
        out.push_back(p);
    }
    return out;
}

std::vector<EmitterSample> buildEmitterSamples(const Scene& scene, uint32_t count) {
    std::vector<EmitterTriangle> emitters = collectEmitters(scene);
    if (count == 0 || emitters.empty()) return {};

    // Stratify the K samples over the cumulative power: sample k -> share (k + 0.5) / K
    double totalPower = 0.0;
    for (const EmitterTriangle& e : emitters)
        totalPower += e.power;
    std::vector<uint32_t> perTriangle(emitters.size(), 0);
    double cumulative = 0.0;
    size_t tri = 0;
    for (uint32_t k = 0; k < count; ++k) {
        double u = (double(k) + 0.5) / double(count) * totalPower;
        while (tri + 1 < emitters.size() && cumulative + emitters[tri].power <= u) {
            cumulative += emitters[tri].power;
            ++tri;
        }
        ++perTriangle[tri];
    }

    // Place n_i Hammersley points per triangle, each representing area_i / n_i
    std::vector<EmitterSample> samples;
    samples.reserve(count);
    double sampledPower = 0.0;
    for (size_t i = 0; i < emitters.size(); ++i) {
        const EmitterTriangle& e = emitters[i];
        uint32_t n = perTriangle[i];
        if (n == 0) continue;
        sampledPower += e.power;
        for (uint32_t j = 0; j < n; ++j) {
            // Uniform square -> triangle warp (pbrt-v3 UniformSampleTriangle)
            float u1 = (float(j) + 0.5f) / float(n);
            float u2 = radicalInverse2(j);
            float s = std::sqrt(u1);
            float b0 = 1.0f - s, b1 = u2 * s, b2 = 1.0f - b0 - b1;
            EmitterSample sample;
            sample.position = b0 * e.p0 + b1 * e.p1 + b2 * e.p2;
            glm::vec2 uv = b0 * e.uv0 + b1 * e.uv1 + b2 * e.uv2;
            sample.normal = e.normal;
            sample.area = e.area / float(n);
            sample.intensity = emittedRadiance(scene, *e.material, uv) * sample.area;
            sample.twoSided = e.material->doubleSided;
            sample.triangle = e.triangle;
            samples.push_back(sample);
        }
    }

    // Spread the power of unsampled triangles over all samples
    float scale = sampledPower > 0.0 ? float(totalPower / sampledPower) : 1.0f;
    for (EmitterSample& s : samples)
        s.intensity *= scale;
    return samples;
}

}  // namespace gilab
