#include "reference/integrator.h"

#include <cmath>
#include <limits>

#include "reference/bsdf.h"
#include "reference/embree_scene.h"
#include "reference/lights.h"
#include "reference/sampling.h"
#include "reference/texture_lookup.h"

namespace gilab::ref {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
/** Shadow rays to a point stop this fraction short of it (pbrt's ShadowEpsilon idea): the far
 *  end is a light or an emitter point already moved off its surface towards the receiver. */
constexpr float kShadowTFar = 1.0f - 1.0e-5f;

/** What the path needs of a hit: position, normals, uv and material (scene.glsl helpers). */
struct SurfacePoint {
    glm::vec3 p;
    glm::vec3 ng;  // unit geometric normal on the side of wo
    glm::vec3 n;   // unit shading normal, flipped onto ng's side
    glm::vec2 uv;
    bool frontFace;  // wo is on the counter-clockwise side
    const Material* material;
};

SurfacePoint makeSurfacePoint(const Scene& scene, const MeshTriangle& tri, const RayHit& hit,
                              const glm::vec3& wo) {
    SurfacePoint sp;
    const float b1 = hit.u, b2 = hit.v, b0 = 1.0f - b1 - b2;
    sp.p = tri.p0 + b1 * tri.e1 + b2 * tri.e2;
    // Facing from the geometric normal, then the shading normal on the viewer's side of it
    // (gbuffer.frag; docs/shared_passes.md, "Facing")
    const glm::vec3 ngCcw = tri.area > 0.0f ? tri.n : wo;
    sp.frontFace = glm::dot(ngCcw, wo) >= 0.0f;
    sp.ng = sp.frontFace ? ngCcw : -ngCcw;
    const Vertex& v0 = scene.vertices[tri.v[0]];
    const Vertex& v1 = scene.vertices[tri.v[1]];
    const Vertex& v2 = scene.vertices[tri.v[2]];
    const glm::vec3 nInterp = b0 * v0.normal + b1 * v1.normal + b2 * v2.normal;
    const float len = glm::length(nInterp);
    sp.n = (len > 0.0f && std::isfinite(len)) ? nInterp / len : sp.ng;
    if (glm::dot(sp.n, sp.ng) < 0.0f) sp.n = -sp.n;
    sp.uv = b0 * v0.uv + b1 * v1.uv + b2 * v2.uv;
    sp.material = &scene.materials[tri.material];
    return sp;
}

glm::vec2 triangleUv(const Scene& scene, const MeshTriangle& tri, glm::vec2 bary) {
    return (1.0f - bary.x - bary.y) * scene.vertices[tri.v[0]].uv +
           bary.x * scene.vertices[tri.v[1]].uv + bary.y * scene.vertices[tri.v[2]].uv;
}

bool isBlack(const glm::vec3& v) {
    return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f;
}

}  // namespace

Integrator::Integrator(const Scene& scene, const ReferenceSettings& settings,
                       const EmbreeScene& mesh, const LightSampler& lights,
                       const TextureLookup& textures)
    : m_scene(scene),
      m_settings(settings),
      m_mesh(mesh),
      m_lights(lights),
      m_textures(textures),
      m_offsetScale(rayOffsetScale(scene.caps.bounds.lo, scene.caps.bounds.hi)) {}

void Integrator::radiance(const Ray& ray, const RayHit* cameraHit, Sampler& sampler,
                          PathRadiance& out, PathCounters& counters,
                          std::vector<RecordedRay>* sink) const {
    for (glm::vec3& l : out.L)
        l = glm::vec3(0.0f);
    const Estimator estimator = m_settings.estimator;
    const bool useNee = estimator != Estimator::BsdfOnly && m_lights.hasEmitters();
    const bool useBsdfHits = estimator != Estimator::NeeOnly && m_lights.hasEmitters();
    const int lastVertex = m_settings.maxBounces + 1;

    // Camera ray
    glm::vec3 rayO = ray.origin, rayD = ray.direction;
    RayHit hit;
    bool found;
    if (cameraHit) {
        found = cameraHit->prim != ~0u;
        hit = *cameraHit;
    } else {
        found = m_mesh.intersect(rayO, rayD, 0.0f, kInfinity, hit);
    }
    ++counters.cameraRays;
    if (sink) sink->push_back({rayO, rayD, 0.0f, kInfinity, false});

    glm::vec3 beta(1.0f);
    float prevBsdfPdf = 0.0f;
    for (int k = 1; found; ++k) {
        const MeshTriangle& tri = m_mesh.triangle(hit.prim);
        const glm::vec3 wo = -rayD;
        const SurfacePoint sp = makeSurfacePoint(m_scene, tri, hit, wo);
        const Material& mat = *sp.material;

        // Emission towards the previous vertex: the camera (emission layer) or vertex k - 1
        if (mat.isEmissive() && (sp.frontFace || mat.doubleSided)) {
            const glm::vec3 le = lookupEmission(mat, m_textures, sp.uv);
            if (k == 1) {
                out.L[int(Layer::Emission)] += le;
            } else if (useBsdfHits) {
                float w = 1.0f;
                if (estimator == Estimator::Mis) {
                    // Light pdf of this point in solid angle at vertex k - 1 (rayD is unit)
                    const float cosL = std::abs(glm::dot(tri.n, wo));
                    const float pdfLight =
                        cosL > 0.0f ? m_lights.pdfArea(hit.prim) * hit.t * hit.t / cosL : 0.0f;
                    w = powerHeuristic(prevBsdfPdf, pdfLight);
                }
                out.L[int(layerForVertex(k - 1))] += beta * le * w;
            }
        }
        if (k > lastVertex) break;

        const glm::vec4 baseColor = lookupBaseColor(mat, m_textures, sp.uv);
        const glm::vec2 metalRough = lookupMetalRough(mat, m_textures, sp.uv);
        const Bsdf bsdf(sp.n, glm::vec3(baseColor), metalRough.x, metalRough.y);
        const glm::vec3 origin = offsetRayOrigin(sp.p, sp.ng, m_offsetScale);
        glm::vec3& Lk = out.L[int(layerForVertex(k))];

        // Next-event estimation: every punctual light (delta lights, lights.glsl formulas)
        for (size_t i = 0; i < m_lights.punctualCount(); ++i) {
            glm::vec3 wi;
            float dist;
            const glm::vec3 ePerp = m_lights.punctualIrradiance(i, sp.p, wi, dist);
            const float cosTheta = glm::dot(sp.n, wi);
            if (cosTheta <= 0.0f || isBlack(ePerp) || glm::dot(sp.ng, wi) <= 0.0f) continue;
            const glm::vec3 f = bsdf.eval(wo, wi);
            if (isBlack(f)) continue;
            const Light& light = m_lights.punctual(i);
            const bool directional = light.type == LightType::Directional;
            const glm::vec3 dir = directional ? wi : light.position - origin;
            const float tFar = directional ? kInfinity : kShadowTFar;
            ++counters.shadowRays;
            if (sink) sink->push_back({origin, dir, 0.0f, tFar, true});
            if (m_mesh.occluded(origin, dir, 0.0f, tFar)) continue;
            Lk += beta * f * ePerp * cosTheta;
        }

        // Next-event estimation: one point on the emissive triangles, by power
        if (useNee) {
            const double uSelect = sampler.get1DDouble();
            const glm::vec2 uPoint = sampler.get2D();
            EmitterSample es;
            if (m_lights.sampleEmitter(uSelect, uPoint, es)) {
                const MeshTriangle& lt = m_mesh.triangle(es.prim);
                const Material& lm = m_scene.materials[lt.material];
                const glm::vec3 toLight = es.p - sp.p;
                const float dist2 = glm::dot(toLight, toLight);
                const float dist = std::sqrt(dist2);
                const glm::vec3 wi = toLight / dist;
                const float cosL = glm::dot(lt.n, -wi);
                const float cosTheta = glm::dot(sp.n, wi);
                const bool emitsToX = lm.doubleSided ? cosL != 0.0f : cosL > 0.0f;
                if (dist2 > 0.0f && emitsToX && cosTheta > 0.0f && glm::dot(sp.ng, wi) > 0.0f) {
                    const glm::vec2 uvL = triangleUv(m_scene, lt, es.bary);
                    const glm::vec3 le = isCutOut(lm, m_textures, uvL)
                                             ? glm::vec3(0.0f)
                                             : lookupEmission(lm, m_textures, uvL);
                    const glm::vec3 f = bsdf.eval(wo, wi);
                    if (!isBlack(le) && !isBlack(f)) {
                        const float pdfLight = es.pdfArea * dist2 / std::abs(cosL);
                        const float w = estimator == Estimator::Mis
                                            ? powerHeuristic(pdfLight, bsdf.pdf(wo, wi))
                                            : 1.0f;
                        const glm::vec3 target =
                            offsetRayOrigin(es.p, cosL > 0.0f ? lt.n : -lt.n, m_offsetScale);
                        const glm::vec3 dir = target - origin;
                        ++counters.shadowRays;
                        if (sink) sink->push_back({origin, dir, 0.0f, kShadowTFar, true});
                        if (!m_mesh.occluded(origin, dir, 0.0f, kShadowTFar))
                            Lk += beta * f * le * (cosTheta * w / pdfLight);
                    }
                }
            }
        }

        // The last vertex only traces on if a BSDF-sampled emitter hit can still add light
        if (k == lastVertex && !useBsdfHits) break;

        // Sample the BSDF for the next vertex
        const float uLobe = sampler.get1D();
        const glm::vec2 uDir = sampler.get2D();
        BsdfSample bs;
        if (!bsdf.sample(wo, uLobe, uDir, bs)) break;
        const float cosTheta = glm::dot(sp.n, bs.wi);
        if (cosTheta <= 0.0f || glm::dot(sp.ng, bs.wi) <= 0.0f || isBlack(bs.f)) break;
        beta *= bs.f * (cosTheta / bs.pdf);
        prevBsdfPdf = bs.pdf;

        // Russian roulette on the continuation from vertex k (bounce k) if enabled
        if (m_settings.rouletteStartBounce >= 0 && k > m_settings.rouletteStartBounce) {
            const float uRr = sampler.get1D();
            const float survive = std::min(1.0f, maxComponent(beta));
            if (!(uRr < survive)) break;
            beta /= survive;
        }

        rayO = origin;
        rayD = bs.wi;
        found = m_mesh.intersect(rayO, rayD, 0.0f, kInfinity, hit);
        ++counters.bounceRays;
        if (sink) sink->push_back({rayO, rayD, 0.0f, kInfinity, false});
    }

    glm::vec3 full(0.0f);
    for (int l = int(Layer::Emission); l < kLayerCount; ++l)
        full += out.L[l];
    out.L[int(Layer::Full)] = full;
}

}  // namespace gilab::ref
