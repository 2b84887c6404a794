#pragma once
/**
 * Validation of the GPU ray tracer (core/rt: rt_trace.glsl on the BVH of core/rt/bvh.h)
 * against Embree on one scene (docs/gpu_rays.md, "Validation"; `gilab bench rt`).
 *
 * Embree sees a plain copy of the scene's triangles: one RTC_GEOMETRY_TYPE_TRIANGLE in a scene
 * with RTC_SCENE_FLAG_ROBUST, no alpha filters (the GPU tracer has no alpha test either; the
 * path tracer's reference/embree_scene.h applies alpha cut-outs and is not used here).
 *
 * Rays, deterministic from the seed (counter-based per ray, the same whatever the thread count):
 * even ray indices start uniformly in the scene's triangle bounds grown by 5 % (2.5 % of the
 * extent on each side), odd ones on a random surface point (area-weighted) moved by
 * 1e-3 x the bounds' diagonal along the geometric normal, to either side; directions uniform on
 * the unit sphere; t in [0, inf). Each is traced for the closest hit by Embree (rtcIntersect1 in
 * a TBB parallel loop) and by rt::RayQuery; then a segment along the same ray, to Embree's
 * closest t x U(0.5, 1.5) (to U(0, 2) x diagonal where Embree missed), is traced for occlusion
 * by both (rtcOccluded1, rt::QueryMode::Occluded).
 *
 * The rules (`passed()`), with tolerance tol = 1e-4 x max(t_embree, 1e-6 x diagonal):
 *  - hit/miss agreement >= 99.99 % of the rays;
 *  - occlusion agreement >= 99.99 % of the segments;
 *  - where both hit, |t_gpu - t_embree| > tol (a t outlier) on <= 0.01 % of those rays;
 *  - where both hit different triangles, the GPU's triangle must be a tie: the ray meets it
 *    (in double, from the scene's vertices) at a t within tol of Embree's t, inside it up to a
 *    distance tol (coplanar duplicates, shared edges); other mismatches <= 0.01 % of those rays.
 */
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/rt/bvh.h"

namespace gilab {
struct Scene;
namespace vk {
class Context;
}
}  // namespace gilab

namespace gilab::ref {

/** Largest fraction of disagreements each rule allows (0.01 %). */
inline constexpr double kRtMaxDisagreement = 1e-4;
/** Relative t tolerance: |t_gpu - t_embree| <= kRtRelTolerance x max(t_embree, 1e-6 diag). */
inline constexpr double kRtRelTolerance = 1e-4;

struct RtValidationOptions {
    uint64_t rays = 1'000'000;
    uint64_t seed = 1;
    bool progress = true;  // a progress line (core/util/progress.h) while tracing
};

struct RtValidationResult {
    std::string scene;
    uint64_t triangles = 0;  // the scene's, degenerate ones included
    double diagonal = 0.0;   // of the triangles' bounds
    rt::BvhStats bvh;

    // Closest hit
    uint64_t rays = 0;
    uint64_t embreeHits = 0;
    uint64_t gpuHits = 0;
    uint64_t bothHit = 0;
    uint64_t hitMissDisagreements = 0;
    uint64_t tOutliers = 0;
    double maxRelTError = 0.0;  // max |t_gpu - t_embree| / max(t_embree, 1e-6 diag), both hit
    std::string maxRelTRay;     // the ray with that error, as the examples print it
    uint64_t primitiveTies = 0;
    uint64_t primitiveMismatches = 0;  // not ties

    // Occlusion (segments)
    uint64_t embreeOccluded = 0;
    uint64_t occlusionDisagreements = 0;

    // Cost. GPU: summed timestamp time of the trace dispatches, and the wall time of the
    // blocking RayQuery::trace calls (upload, submit, wait, read-back). Embree: wall time of the
    // TBB loop.
    double gpuSeconds = 0.0;
    double gpuWallSeconds = 0.0;
    double gpuOcclusionSeconds = 0.0;
    double gpuOcclusionWallSeconds = 0.0;
    double embreeSeconds = 0.0;
    double embreeOcclusionSeconds = 0.0;
    double embreeBuildMs = 0.0;

    /** The first disagreements (up to 8), one line each, for diagnosis. */
    std::vector<std::string> examples;

    double gpuRaysPerSecond() const { return gpuSeconds > 0.0 ? double(rays) / gpuSeconds : 0.0; }
    double gpuWallRaysPerSecond() const {
        return gpuWallSeconds > 0.0 ? double(rays) / gpuWallSeconds : 0.0;
    }
    double embreeRaysPerSecond() const {
        return embreeSeconds > 0.0 ? double(rays) / embreeSeconds : 0.0;
    }
    /** Every rule holds (see the file comment). */
    bool passed() const { return failures().empty(); }
    /** The rules that fail, one sentence each ("" when passed). */
    std::string failures() const;
};

/** Validates the GPU ray tracer on `scene` (builds the GPU BVH and a plain Embree scene). */
RtValidationResult validateGpuRayTracer(vk::Context& ctx, const Scene& scene,
                                        const RtValidationOptions& options = {});

/** One validation ray: origin, direction (unit), the segment's length for occlusion is chosen
 *  after the closest-hit pass. */
struct RtValidationRay {
    glm::vec3 origin{0.0f};
    glm::vec3 direction{0.0f, 0.0f, 1.0f};
};

/** The validation's rays (deterministic in `seed`; see the file comment). */
std::vector<RtValidationRay> makeRtValidationRays(const Scene& scene, uint64_t count,
                                                  uint64_t seed);

/** Whether the ray o + t d meets triangle `tri` of the scene (double precision, from the scene's
 *  vertices) at a t within `tolerance` of `t`, at a point no farther than `tolerance` from the
 *  triangle: the tie rule of the validation. */
bool rtIsTie(const Scene& scene, uint32_t tri, const glm::vec3& o, const glm::vec3& d, double t,
             double tolerance);

}  // namespace gilab::ref
