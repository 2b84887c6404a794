#include "reference/rt_validation.h"

#include "core/util/random.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/rt/gpu_bvh.h"
#include "core/rt/ray_query.h"
#include "core/scene/scene.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "core/util/random.h"

namespace gilab::ref {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// ---------------------------------------------------------------------------------------------
// Deterministic random numbers: one splitmix64 stream per (seed, stream, ray index).

class Rng {
public:
    Rng(uint64_t seed, uint64_t stream, uint64_t index)
        : m_state(mix64(mix64(seed + kSplitMixIncrement * (stream + 1)) ^ index)) {}
    uint64_t next() {
        m_state += kSplitMixIncrement;
        return mix64(m_state);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }  // [0, 1)

private:
    uint64_t m_state;
};

glm::dvec3 uniformSphere(Rng& rng) {
    const double z = 1.0 - 2.0 * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * M_PI * rng.uniform();
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// ---------------------------------------------------------------------------------------------
// Scene geometry helpers

struct Tri {
    glm::dvec3 a, b, c;
};

Tri triangleOf(const Scene& scene, uint32_t t) {
    const auto p = [&](int k) {
        return glm::dvec3(scene.vertices[scene.indices[3 * size_t(t) + size_t(k)]].position);
    };
    return {p(0), p(1), p(2)};
}

/** The triangles' bounds (every triangle, degenerate ones too); invalid when there are none. */
Bounds triangleBounds(const Scene& scene) {
    Bounds b;
    for (uint32_t index : scene.indices)
        if (index < scene.vertices.size()) b.extend(scene.vertices[index].position);
    return b;
}

/** Closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5). */
glm::dvec3 closestPointOnTriangle(const glm::dvec3& p, const Tri& t) {
    const glm::dvec3 ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return t.a;
    const glm::dvec3 bp = p - t.b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return t.b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return t.a + (d1 / (d1 - d3)) * ab;
    const glm::dvec3 cp = p - t.c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return t.c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return t.a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return t.b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (t.c - t.b);
    const double denom = 1.0 / (va + vb + vc);
    return t.a + ab * (vb * denom) + ac * (vc * denom);
}

// ---------------------------------------------------------------------------------------------
// The plain Embree scene: the scene's triangles, robust, no filters.

class PlainEmbree {
public:
    explicit PlainEmbree(const Scene& scene) {
        const auto start = Clock::now();
        m_device = rtcNewDevice("verbose=0");
        if (!m_device)
            throw Error("Embree: rtcNewDevice failed (error " +
                        std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
        m_scene = rtcNewScene(m_device);
        rtcSetSceneFlags(m_scene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(m_scene, RTC_BUILD_QUALITY_HIGH);
        const size_t triCount = scene.triangleCount();
        if (triCount > 0) {
            RTCGeometry geom = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
            auto* positions = static_cast<float*>(
                rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                        3 * sizeof(float), scene.vertices.size()));
            auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
                geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triCount));
            check("allocating the geometry buffers");
            for (size_t i = 0; i < scene.vertices.size(); ++i) {
                const glm::vec3& p = scene.vertices[i].position;
                positions[3 * i + 0] = p.x;
                positions[3 * i + 1] = p.y;
                positions[3 * i + 2] = p.z;
            }
            for (size_t i = 0; i < 3 * triCount; ++i) {
                if (scene.indices[i] >= scene.vertices.size())
                    throw Error("scene '" + scene.name + "': triangle " + std::to_string(i / 3) +
                                " indexes vertex " + std::to_string(scene.indices[i]) + " of " +
                                std::to_string(scene.vertices.size()));
                indices[i] = scene.indices[i];
            }
            rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
            rtcCommitGeometry(geom);
            rtcAttachGeometryByID(m_scene, geom, 0);
            rtcReleaseGeometry(geom);
            check("building the triangle geometry");
        }
        rtcCommitScene(m_scene);
        check("building the BVH");
        buildMs = 1e3 * secondsSince(start);
    }
    ~PlainEmbree() {
        if (m_scene) rtcReleaseScene(m_scene);
        if (m_device) rtcReleaseDevice(m_device);
    }
    PlainEmbree(const PlainEmbree&) = delete;
    PlainEmbree& operator=(const PlainEmbree&) = delete;

    /** Closest hit; prim = kNoHit on a miss. */
    void intersect(const glm::vec3& o, const glm::vec3& d, float tMin, float tMax, float& t,
                   uint32_t& prim, glm::vec2& bary) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRayHit rh{};
        rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
        rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
        rh.ray.tnear = tMin;
        rh.ray.tfar = tMax;
        rh.ray.mask = 0xffffffffu;
        rh.ray.flags = 0;
        rh.ray.time = 0.0f;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(m_scene, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
            t = -1.0f;
            prim = rt::kNoHit;
            bary = glm::vec2(0.0f);
            return;
        }
        t = rh.ray.tfar;
        prim = rh.hit.primID;
        bary = glm::vec2(rh.hit.u, rh.hit.v);
    }

    bool occluded(const glm::vec3& o, const glm::vec3& d, float tMin, float tMax) const {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        RTCRay ray{};
        ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
        ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
        ray.tnear = tMin;
        ray.tfar = tMax;
        ray.mask = 0xffffffffu;
        ray.flags = 0;
        ray.time = 0.0f;
        rtcOccluded1(m_scene, &context, &ray);
        return ray.tfar < 0.0f;  // -inf when occluded
    }

    double buildMs = 0.0;

private:
    void check(const char* what) const {
        const RTCError code = rtcGetDeviceError(m_device);
        if (code != RTC_ERROR_NONE)
            throw Error(std::string("Embree: ") + what + ": error " + std::to_string(int(code)));
    }

    RTCDevice m_device = nullptr;
    RTCScene m_scene = nullptr;
};

std::string vecText(const glm::vec3& v) {
    char buf[96];
    std::snprintf(buf, sizeof(buf), "(%.9g, %.9g, %.9g)", v.x, v.y, v.z);
    return buf;
}

std::string hitText(float t, uint32_t prim) {
    if (prim == rt::kNoHit) return "miss";
    char buf[64];
    std::snprintf(buf, sizeof(buf), "t %.9g tri %u", t, prim);
    return buf;
}

std::string percentText(uint64_t n, uint64_t of) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.4f %%", of > 0 ? 100.0 * double(n) / double(of) : 0.0);
    return buf;
}

}  // namespace

std::string RtValidationResult::failures() const {
    std::vector<std::string> out;
    auto rule = [&](uint64_t bad, uint64_t of, const std::string& what) {
        if (double(bad) > kRtMaxDisagreement * double(of))
            out.push_back(what + ": " + std::to_string(bad) + " of " + std::to_string(of) + " (" +
                          percentText(bad, of) + " > 0.01 %)");
    };
    rule(hitMissDisagreements, rays, "hit/miss disagreements");
    rule(occlusionDisagreements, rays, "occlusion disagreements");
    rule(tOutliers, bothHit, "t outliers (relative error > 1e-4)");
    rule(primitiveMismatches, bothHit, "different triangles that are not ties");
    std::string text;
    for (const std::string& s : out)
        text += (text.empty() ? "" : "; ") + s;
    return text;
}

std::vector<RtValidationRay> makeRtValidationRays(const Scene& scene, uint64_t count,
                                                  uint64_t seed) {
    std::vector<RtValidationRay> rays(count);
    Bounds bounds = triangleBounds(scene);
    if (!bounds.valid()) bounds = Bounds{glm::vec3(-1.0f), glm::vec3(1.0f)};
    const glm::dvec3 lo(bounds.lo), hi(bounds.hi);
    const double diagonal = std::max(glm::length(hi - lo), 1e-6);
    // Grown by 5 %: 2.5 % of the extent each side (of the diagonal where an extent is 0)
    glm::dvec3 margin = 0.025 * (hi - lo);
    for (int k = 0; k < 3; ++k)
        if (margin[k] <= 0.0) margin[k] = 0.025 * diagonal;
    const glm::dvec3 boxLo = lo - margin, boxSize = (hi - lo) + 2.0 * margin;

    // Area-weighted triangle choice for the surface origins
    const size_t triCount = scene.triangleCount();
    std::vector<double> cdf(triCount);
    double total = 0.0;
    for (size_t t = 0; t < triCount; ++t) {
        const Tri tri = triangleOf(scene, uint32_t(t));
        const double area = 0.5 * glm::length(glm::cross(tri.b - tri.a, tri.c - tri.a));
        if (std::isfinite(area)) total += area;
        cdf[t] = total;
    }
    const bool surfaces = total > 0.0;
    const double offset = 1e-3 * diagonal;

    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, count, 4096), [&](const auto& range) {
        for (uint64_t i = range.begin(); i != range.end(); ++i) {
            Rng rng(seed, 0, i);
            glm::dvec3 o;
            if (i % 2 == 0 || !surfaces) {
                o = boxLo + boxSize * glm::dvec3(rng.uniform(), rng.uniform(), rng.uniform());
            } else {
                const double pick = rng.uniform() * total;
                size_t t = size_t(std::upper_bound(cdf.begin(), cdf.end(), pick) - cdf.begin());
                t = std::min(t, triCount - 1);
                while (t > 0 && cdf[t] == cdf[t - 1])
                    --t;  // a zero-area triangle: its neighbour
                const Tri tri = triangleOf(scene, uint32_t(t));
                const double su = std::sqrt(rng.uniform()), v = rng.uniform();
                const double b1 = su * (1.0 - v), b2 = su * v;
                const glm::dvec3 n = glm::normalize(glm::cross(tri.b - tri.a, tri.c - tri.a));
                const double side = rng.uniform() < 0.5 ? -1.0 : 1.0;
                o = tri.a + b1 * (tri.b - tri.a) + b2 * (tri.c - tri.a) + side * offset * n;
            }
            rays[i].origin = glm::vec3(o);
            rays[i].direction = glm::vec3(uniformSphere(rng));
        }
    });
    return rays;
}

bool rtIsTie(const Scene& scene, uint32_t triIndex, const glm::vec3& o, const glm::vec3& d,
             double t, double tolerance) {
    if (triIndex >= scene.triangleCount()) return false;
    const Tri tri = triangleOf(scene, triIndex);
    const glm::dvec3 od(o), dd(d);
    const glm::dvec3 n = glm::cross(tri.b - tri.a, tri.c - tri.a);
    const double denom = glm::dot(n, dd);
    double tPlane = t;  // a ray in the triangle's plane: judged at Embree's point
    if (std::abs(denom) > 1e-12 * glm::length(n) * glm::length(dd))
        tPlane = glm::dot(n, tri.a - od) / denom;
    if (!(std::abs(tPlane - t) <= tolerance)) return false;
    const glm::dvec3 p = od + tPlane * dd;
    return glm::length(p - closestPointOnTriangle(p, tri)) <= tolerance;
}

RtValidationResult validateGpuRayTracer(vk::Context& ctx, const Scene& scene,
                                        const RtValidationOptions& options) {
    RtValidationResult r;
    r.scene = scene.name;
    r.triangles = scene.triangleCount();
    r.rays = options.rays;
    {
        const Bounds b = triangleBounds(scene);
        r.diagonal = b.valid() ? glm::length(glm::dvec3(b.hi) - glm::dvec3(b.lo)) : 0.0;
    }
    const double tFloor = 1e-6 * r.diagonal;

    rt::GpuBvh gpuBvh(ctx, scene, "rt_validation/bvh");
    r.bvh = gpuBvh.stats();
    const PlainEmbree embree(scene);
    r.embreeBuildMs = embree.buildMs;
    rt::RayQuery query(ctx, gpuBvh);

    const std::vector<RtValidationRay> rays =
        makeRtValidationRays(scene, options.rays, options.seed);
    const size_t n = rays.size();
    const float inf = std::numeric_limits<float>::infinity();

    // Closest hit: Embree
    std::vector<float> eT(n);
    std::vector<uint32_t> ePrim(n);
    {
        const auto start = Clock::now();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const auto& range) {
            for (size_t i = range.begin(); i != range.end(); ++i) {
                glm::vec2 bary;
                embree.intersect(rays[i].origin, rays[i].direction, 0.0f, inf, eT[i], ePrim[i],
                                 bary);
            }
        });
        r.embreeSeconds = secondsSince(start);
    }

    // The GPU, in chunks (progress line between them)
    constexpr size_t kChunk = size_t(1) << 18;
    std::optional<Progress> progress;
    if (options.progress) progress.emplace("rt validation " + scene.name, 2 * n);
    auto traceGpu = [&](const std::vector<rt::QueryRay>& queries, rt::QueryMode mode,
                        size_t doneBefore, double& gpuSeconds, double& wallSeconds) {
        std::vector<rt::QueryHit> hits;
        hits.reserve(queries.size());
        for (size_t first = 0; first < queries.size(); first += kChunk) {
            const size_t count = std::min(kChunk, queries.size() - first);
            const std::vector<rt::QueryRay> chunk(queries.begin() + first,
                                                  queries.begin() + first + count);
            double seconds = 0.0;
            const auto start = Clock::now();
            const std::vector<rt::QueryHit> h = query.trace(chunk, mode, &seconds);
            wallSeconds += secondsSince(start);
            gpuSeconds += seconds;
            hits.insert(hits.end(), h.begin(), h.end());
            if (progress) progress->update(doneBefore + first + count);
        }
        return hits;
    };

    std::vector<rt::QueryRay> queries(n);
    for (size_t i = 0; i < n; ++i)
        queries[i] = rt::QueryRay{rays[i].origin, 0.0f, rays[i].direction, inf};
    const std::vector<rt::QueryHit> gHits =
        traceGpu(queries, rt::QueryMode::Closest, 0, r.gpuSeconds, r.gpuWallSeconds);

    // Segments for occlusion: to Embree's t x U(0.5, 1.5), or U(0, 2) x diagonal on a miss
    std::vector<float> segment(n);
    const double missLength = 2.0 * std::max(r.diagonal, 1e-6);
    for (size_t i = 0; i < n; ++i) {
        Rng rng(options.seed, 1, i);
        const double u = rng.uniform();
        segment[i] =
            ePrim[i] != rt::kNoHit ? float(double(eT[i]) * (0.5 + u)) : float(u * missLength);
        queries[i].tMax = segment[i];
    }
    std::vector<uint8_t> eOccluded(n);
    {
        const auto start = Clock::now();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const auto& range) {
            for (size_t i = range.begin(); i != range.end(); ++i)
                eOccluded[i] = embree.occluded(rays[i].origin, rays[i].direction, 0.0f, segment[i]);
        });
        r.embreeOcclusionSeconds = secondsSince(start);
    }
    const std::vector<rt::QueryHit> gOcc = traceGpu(
        queries, rt::QueryMode::Occluded, n, r.gpuOcclusionSeconds, r.gpuOcclusionWallSeconds);
    if (progress) progress->finish();

    // Comparison
    auto rayText = [&](size_t i) {
        return "ray " + std::to_string(i) + " o " + vecText(rays[i].origin) + " d " +
               vecText(rays[i].direction) + ": ";
    };
    auto example = [&](size_t i, const std::string& what) {
        if (r.examples.size() < 8) r.examples.push_back(rayText(i) + what);
    };
    for (size_t i = 0; i < n; ++i) {
        const bool eHit = ePrim[i] != rt::kNoHit;
        const bool gHit = gHits[i].triangle != rt::kNoHit;
        r.embreeHits += eHit;
        r.gpuHits += gHit;
        if (eHit != gHit) {
            ++r.hitMissDisagreements;
            example(i, "hit/miss: embree " + hitText(eT[i], ePrim[i]) + ", gpu " +
                           hitText(gHits[i].t, gHits[i].triangle));
        } else if (eHit) {
            ++r.bothHit;
            const double scale = std::max(double(eT[i]), tFloor);
            const double tolerance = kRtRelTolerance * scale;
            const double err = std::abs(double(gHits[i].t) - double(eT[i]));
            const double rel = scale > 0.0 ? err / scale : 0.0;
            if (rel > r.maxRelTError) {
                r.maxRelTError = rel;
                r.maxRelTRay = rayText(i) + "embree " + hitText(eT[i], ePrim[i]) + ", gpu " +
                               hitText(gHits[i].t, gHits[i].triangle);
            }
            if (!(err <= tolerance)) {
                ++r.tOutliers;
                example(i, "t: embree " + hitText(eT[i], ePrim[i]) + ", gpu " +
                               hitText(gHits[i].t, gHits[i].triangle));
            }
            if (gHits[i].triangle != ePrim[i]) {
                if (rtIsTie(scene, gHits[i].triangle, rays[i].origin, rays[i].direction,
                            double(eT[i]), tolerance)) {
                    ++r.primitiveTies;
                } else {
                    ++r.primitiveMismatches;
                    example(i, "triangle: embree " + hitText(eT[i], ePrim[i]) + ", gpu " +
                                   hitText(gHits[i].t, gHits[i].triangle));
                }
            }
        }
        r.embreeOccluded += eOccluded[i];
        const bool gOccluded = gOcc[i].t > 0.5f;
        if (bool(eOccluded[i]) != gOccluded) {
            ++r.occlusionDisagreements;
            char buf[64];
            std::snprintf(buf, sizeof(buf), "%.9g", segment[i]);
            example(i, std::string("occlusion to t ") + buf + ": embree " +
                           (eOccluded[i] ? "occluded" : "free") + ", gpu " +
                           (gOccluded ? "occluded" : "free") + " (closest: embree " +
                           hitText(eT[i], ePrim[i]) + ")");
        }
    }
    return r;
}

}  // namespace gilab::ref
