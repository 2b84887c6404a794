#include "reference/integrator.h"

#include <algorithm>
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
                              const glm::dvec3& p, const glm::vec3& wo) {
    SurfacePoint sp;
    const float b1 = hit.u, b2 = hit.v, b0 = 1.0f - b1 - b2;
    sp.p = glm::vec3(p);
    // Facing from the geometric normal, then the shading normal on the viewer's side of it
    // (gbuffer.frag; docs/shared_passes.md, "Facing")
    const glm::vec3 ngCcw = tri.area > 0.0f ? tri.n : wo;
    sp.frontFace = glm::dot(ngCcw, wo) >= 0.0f;
    sp.ng = sp.frontFace ? ngCcw : -ngCcw;
    const glm::vec3 nInterp = b0 * tri.normal[0] + b1 * tri.normal[1] + b2 * tri.normal[2];
    const float len = glm::length(nInterp);
    sp.n = (len > 0.0f && std::isfinite(len)) ? nInterp / len : sp.ng;
    if (glm::dot(sp.n, sp.ng) < 0.0f) sp.n = -sp.n;
    sp.uv = tri.uvAt(b1, b2);
    sp.material = &scene.materials[tri.material];
    return sp;
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
      m_spawn(mesh) {}

bool Integrator::shade(PathState& p, PathRadiance& out, std::vector<ShadowRay>& shadows) const {
    const Estimator estimator = m_settings.estimator;
    const bool useNee = estimator != Estimator::BsdfOnly && m_lights.hasEmitters();
    const bool useBsdfHits = estimator != Estimator::NeeOnly && m_lights.hasEmitters();
    const int lastVertex = m_settings.maxBounces + 1;
    const int k = p.vertex;
    const RayHit& hit = p.hit;
    const MeshTriangle& tri = m_mesh.triangle(hit.prim);
    const glm::vec3 wo = -p.rayD;
    const glm::dvec3 hitPoint = exactHitPoint(tri, p.rayO, p.rayD, hit.u, hit.v);
    const SurfacePoint sp = makeSurfacePoint(m_scene, tri, hit, hitPoint, wo);
    const Material& mat = *sp.material;
    const glm::vec3 beta = p.beta;
    const TextureFootprint* fp = k == 1 && p.hasFootprint ? &p.footprint : nullptr;

    // Emission towards the previous vertex: the camera (emission layer) or vertex k - 1
    if (mat.isEmissive() && (sp.frontFace || mat.doubleSided)) {
        const glm::vec3 le = lookupEmission(mat, m_textures, sp.uv, fp);
        if (k == 1) {
            out.L[int(Layer::Emission)] += le;
        } else if (useBsdfHits) {
            float w = 1.0f;
            if (estimator == Estimator::Mis) {
                // Light pdf of this point in solid angle at vertex k - 1 (rayD is unit)
                const float cosL = std::abs(glm::dot(tri.n, wo));
                const float pdfLight =
                    cosL > 0.0f ? m_lights.pdfArea(hit.prim) * hit.t * hit.t / cosL : 0.0f;
                w = powerHeuristic(p.prevBsdfPdf, pdfLight);
            }
            out.L[int(layerForVertex(k - 1))] += beta * le * w;
        }
    }
    if (k > lastVertex) return false;

    const glm::vec4 baseColor = lookupBaseColor(mat, m_textures, sp.uv, fp);
    const glm::vec2 metalRough = lookupMetalRough(mat, m_textures, sp.uv, fp);
    const Bsdf bsdf(sp.n, glm::vec3(baseColor), metalRough.x, metalRough.y);
    // Rays leave from a point in free space on wo's side of every nearby surface (spawn.h)
    const glm::vec3 origin = m_spawn.origin(hitPoint, hit.prim, wo);
    const int layer = int(layerForVertex(k));

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
        shadows.push_back({origin, dir, tFar, beta * f * ePerp * cosTheta, p.slot, layer});
    }

    // Next-event estimation: one point on the emissive triangles, by power
    if (useNee) {
        const double uSelect = p.sampler.get1DDouble();
        const glm::vec2 uPoint = p.sampler.get2D();
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
                const glm::vec2 uvL = lt.uvAt(es.bary.x, es.bary.y);
                const glm::vec3 le = isCutOut(lm, m_textures, uvL)
                                         ? glm::vec3(0.0f)
                                         : lookupEmission(lm, m_textures, uvL);
                const glm::vec3 f = bsdf.eval(wo, wi);
                if (!isBlack(le) && !isBlack(f)) {
                    const float pdfLight = es.pdfArea * dist2 / std::abs(cosL);
                    const float w = estimator == Estimator::Mis
                                        ? powerHeuristic(pdfLight, bsdf.pdf(wo, wi))
                                        : 1.0f;
                    const glm::vec3 target = m_spawn.origin(glm::dvec3(es.p), es.prim, -wi);
                    shadows.push_back({origin, target - origin, kShadowTFar,
                                       beta * f * le * (cosTheta * w / pdfLight), p.slot, layer});
                }
            }
        }
    }

    // The last vertex only traces on if a BSDF-sampled emitter hit can still add light
    if (k == lastVertex && !useBsdfHits) return false;

    // Sample the BSDF for the next vertex
    const float uLobe = p.sampler.get1D();
    const glm::vec2 uDir = p.sampler.get2D();
    BsdfSample bs;
    if (!bsdf.sample(wo, uLobe, uDir, bs)) return false;
    const float cosTheta = glm::dot(sp.n, bs.wi);
    if (cosTheta <= 0.0f || glm::dot(sp.ng, bs.wi) <= 0.0f || isBlack(bs.f)) return false;
    p.beta *= bs.f * (cosTheta / bs.pdf);
    p.prevBsdfPdf = bs.pdf;

    // Russian roulette on the continuation from vertex k (bounce k) if enabled: survival
    // probability min(1, max component of the throughput / threshold), so only paths whose
    // throughput fell below the threshold are thinned (docs/reference.md, "Russian roulette")
    if (m_settings.rouletteStartBounce >= 0 && k > m_settings.rouletteStartBounce) {
        const float uRr = p.sampler.get1D();
        const float survive = std::min(1.0f, maxComponent(p.beta) / m_settings.rouletteThreshold);
        if (!(uRr < survive)) return false;
        p.beta /= survive;
    }

    p.rayO = origin;
    p.rayD = bs.wi;
    p.vertex = k + 1;
    return true;
}

void Integrator::traceClosest(std::vector<PathState>& paths, const std::vector<uint32_t>& active,
                              bool packets, bool coherent, std::vector<RTCRayHit>& stream) const {
    if (!packets) {
        for (uint32_t i : active) {
            PathState& p = paths[i];
            p.found = m_mesh.intersect(p.rayO, p.rayD, 0.0f, kInfinity, p.hit);
        }
        return;
    }
    if (!coherent) {
        // Bounce rays: one rtcIntersect1M stream (the same hits as 16-wide packets, bit for bit;
        // 2-3 % faster on Sponza, the same on the Cornell box: docs/reference.md "Throughput")
        stream.resize(active.size());
        for (size_t j = 0; j < active.size(); ++j) {
            const PathState& p = paths[active[j]];
            RTCRayHit& r = stream[j];
            r.ray.org_x = p.rayO.x;
            r.ray.org_y = p.rayO.y;
            r.ray.org_z = p.rayO.z;
            r.ray.tnear = 0.0f;
            r.ray.dir_x = p.rayD.x;
            r.ray.dir_y = p.rayD.y;
            r.ray.dir_z = p.rayD.z;
            r.ray.time = 0.0f;
            r.ray.tfar = kInfinity;
            r.ray.mask = ~0u;
            r.ray.id = unsigned(j);
            r.ray.flags = 0;
            r.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            r.hit.primID = RTC_INVALID_GEOMETRY_ID;
            r.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        }
        m_mesh.intersectStream(stream);
        for (size_t j = 0; j < active.size(); ++j) {
            PathState& p = paths[active[j]];
            const RTCRayHit& r = stream[j];
            p.found = r.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            p.hit.prim = p.found ? r.hit.primID : ~0u;
            if (!p.found) continue;
            p.hit.t = r.ray.tfar;
            p.hit.u = r.hit.u;
            p.hit.v = r.hit.v;
        }
        return;
    }
    for (size_t first = 0; first < active.size(); first += 16) {
        const int n = int(std::min<size_t>(16, active.size() - first));
        glm::vec3 o[16], d[16];
        RayHit hits[16];
        for (int j = 0; j < n; ++j) {
            o[j] = paths[active[first + size_t(j)]].rayO;
            d[j] = paths[active[first + size_t(j)]].rayD;
        }
        m_mesh.intersect16(n, o, d, kInfinity, hits, coherent);
        for (int j = 0; j < n; ++j) {
            PathState& p = paths[active[first + size_t(j)]];
            p.found = hits[j].prim != ~0u;
            p.hit = hits[j];
        }
    }
}

void Integrator::traceShadows(const std::vector<ShadowRay>& shadows, std::vector<RTCRay>& stream,
                              PathRadiance* out, bool packets) const {
    // Unoccluded rays add their light in queue order: per path, the order of tracing it alone
    if (!packets) {
        for (const ShadowRay& s : shadows)
            if (!m_mesh.occluded(s.o, s.d, 0.0f, s.tFar)) out[s.slot].L[s.layer] += s.contribution;
        return;
    }
    // One rtcOccluded1M stream over the whole queue (measured fastest for shadow rays)
    stream.resize(shadows.size());
    for (size_t i = 0; i < shadows.size(); ++i) {
        const ShadowRay& s = shadows[i];
        RTCRay& r = stream[i];
        r.org_x = s.o.x;
        r.org_y = s.o.y;
        r.org_z = s.o.z;
        r.tnear = 0.0f;
        r.dir_x = s.d.x;
        r.dir_y = s.d.y;
        r.dir_z = s.d.z;
        r.time = 0.0f;
        r.tfar = s.tFar;
        r.mask = ~0u;
        r.id = unsigned(i);
        r.flags = 0;
    }
    m_mesh.occludedStream(stream);
    for (size_t i = 0; i < shadows.size(); ++i)
        if (!(stream[i].tfar < 0.0f))
            out[shadows[i].slot].L[shadows[i].layer] += shadows[i].contribution;
}

void Integrator::prefetchTriangle(const PathState& p) const {
    if (!p.found) return;
    const char* t = reinterpret_cast<const char*>(&m_mesh.triangle(p.hit.prim));
    __builtin_prefetch(t);
    __builtin_prefetch(t + 64);
}

void Integrator::prefetchTexels(const PathState& p) const {
    if (!p.found) return;
    const MeshTriangle& tri = m_mesh.triangle(p.hit.prim);
    const int texture = m_scene.materials[tri.material].baseColorTexture;
    if (texture >= 0) m_textures.prefetch(texture, tri.uvAt(p.hit.u, p.hit.v));
}

void Integrator::tracePaths(std::vector<PathState>& paths, PathRadiance* out, bool cameraHitsKnown,
                            bool packets, PathCounters& counters, std::vector<RecordedRay>* sink,
                            WaveScratch& scratch) const {
    for (const PathState& p : paths)
        for (glm::vec3& l : out[p.slot].L)
            l = glm::vec3(0.0f);
    std::vector<uint32_t>& active = scratch.active;
    std::vector<uint32_t>& next = scratch.next;
    std::vector<ShadowRay>& shadows = scratch.shadows;
    active.resize(paths.size());
    for (size_t i = 0; i < paths.size(); ++i)
        active[i] = uint32_t(i);

    for (bool cameraRays = true; !active.empty(); cameraRays = false) {
        // 1. The closest hits of every live path's ray (camera rays are coherent)
        if (!(cameraRays && cameraHitsKnown)) {
            traceClosest(paths, active, packets, cameraRays, scratch.bounceRays);
            (cameraRays ? counters.cameraRays : counters.bounceRays) += active.size();
            if (sink)
                for (uint32_t i : active)
                    sink->push_back({paths[i].rayO, paths[i].rayD, 0.0f, kInfinity, false});
        }

        // 2. Shade every hit; the paths that go on form the next wave, in order
        // Hits are random accesses into the mesh and textures: prefetch, a wave at a time, the
        // triangle records, then the base-colour texels (they need the records' uvs), so
        // shading finds them in cache. (Software pipelining, prefetching 16 and 8 hits ahead
        // inside the shading loop, measured no different on Sponza.)
        for (uint32_t i : active)
            prefetchTriangle(paths[i]);
        for (uint32_t i : active)
            prefetchTexels(paths[i]);
        shadows.clear();
        next.clear();
        for (uint32_t i : active) {
            PathState& p = paths[i];
            if (p.found && shade(p, out[p.slot], shadows)) next.push_back(i);
        }

        // 3. Shadow rays of this depth
        counters.shadowRays += shadows.size();
        if (sink)
            for (const ShadowRay& s : shadows)
                sink->push_back({s.o, s.d, 0.0f, s.tFar, true});
        traceShadows(shadows, scratch.shadowRays, out, packets);
        active.swap(next);
    }

    for (const PathState& p : paths) {
        PathRadiance& r = out[p.slot];
        glm::vec3 full(0.0f);
        for (int l = int(Layer::Emission); l < kLayerCount; ++l)
            full += r.L[l];
        r.L[int(Layer::Full)] = full;
    }
}

}  // namespace gilab::ref
