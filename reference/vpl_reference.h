#pragma once
/**
 * The same-VPL reference (Noël & Biri 2014, Table II): a VPL set shaded on the CPU exactly like
 * the GPU gather (shaders/common/vpl_gather.comp, docs/vpl.md) but with exact visibility, one
 * Embree shadow ray per (pixel, VPL) pair, instead of the clustered paraboloid maps. The
 * difference between a technique's VPL image and `exact` is then the visibility approximation
 * alone; `exact` against the path tracer is the error of the VPL set itself.
 *
 * Per covered pixel p (normal n, albedo rho) and valid VPL v (docs/vpl.md, Eq. 6 in watts):
 *   d = v.pos - p, skipped when d.d <= 1e-20 (no direction), l = d / |d|,
 *   g = max(n.l, 0) max(n_v.(-l), 0) / pi, skipped when g <= 0,
 *   E += flux scale[bounce] g / max(d.d, d_min^2) V,   L = rho / pi E  (alpha 1).
 * The per-VPL term is evaluated in float in the gather's order; the sum over VPLs is kept in
 * double (VPL index order, so the image does not depend on the thread count). Differences from
 * the GPU gather: every pixel sees every VPL (no interleaving) and the visibility map layer in
 * normal.w is ignored.
 *
 * Visibility V: one shadow ray on the segment from p + n_p eps_p to v.pos + n_v eps_v (n_p, n_v
 * normalised for the offset), t in [0, 1] of the segment, with
 *   eps_q = max(1e-4 x scene diagonal, 16 FLT_EPSILON max(|q.x|, |q.y|, |q.z|)):
 * the first term clears the BVH's and the G-buffer's rounding at scene scale, the second (16 to 32
 * ULPs of the largest coordinate) keeps the offset meaningful far from the origin. Both ends
 * are moved off their surfaces along the side the light travels (g > 0 puts the VPL in front of
 * n_p and p in front of n_v), so the segment does not hit the receiver or the VPL's own surface.
 *
 * Shadow rays go in 16-ray packets: one rtcOccluded16 per 4 x 4 pixel tile and VPL (the rays
 * converge on the VPL, so they traverse coherently); `packets = false` traces each ray with
 * rtcOccluded1 instead (identical images in the tests and benchmarks). Measured on 2 cores (256 x
 * 144 G-buffer of primary hits, 1024 VPLs): sponza 15 vs 7 Mrays/s, sibenik 22 vs 9.5, Cornell box
 * 25 vs 10.
 *
 * Non-finite input never reaches the output: a covered pixel with a non-finite position,
 * normal or albedo is written as (0, 0, 0, 1) like an uncovered one (vpl_blur.comp) and counted, a
 * valid VPL with a non-finite position, normal or flux is skipped and counted.
 */
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "core/vpl/vpl.h"
#include "reference/embree_scene.h"

namespace gilab::ref {

struct VplReferenceInput {
    uint32_t width = 0, height = 0;
    std::vector<glm::vec4> position;    // per pixel: world xyz, w > 0.5 = covered (G-buffer layout)
    std::vector<glm::vec4> normal;      // per pixel: unit shading normal xyz
    std::vector<glm::vec4> albedo;      // per pixel: diffuse albedo rgb
    std::vector<GpuVpl> vpls;           // valid ones have position.w >= 0.5
    float clampDistance = 0.0f;         // d_min, world units (0 = none), same as the GPU gather
    glm::vec2 bounceScale{1.0f, 1.0f};  // flux multiplier for bounce 1 (flux.w < 1.5) and 2
    bool packets = true;  // 16-ray packets per 4 x 4 tile and VPL; false = one ray at a time
};

struct VplReferenceResult {
    std::vector<glm::vec4> exact;       // outgoing radiance albedo/pi * E, binary shadow-ray V
    std::vector<glm::vec4> unshadowed;  // the same with V = 1 for every VPL
    double rays = 0.0;                  // shadow rays traced
    double seconds = 0.0;               // wall time
    uint64_t invalidPixels = 0;         // covered pixels with non-finite input (written as 0)
    uint64_t invalidVpls = 0;           // valid VPLs with non-finite data (skipped)
};

/** The shadow-ray offset eps_q of a point q (see above) in a scene of the given diagonal. */
float vplShadowRayOffset(const glm::vec3& q, float sceneDiagonal);

/**
 * Shades every covered pixel of `in` with every valid VPL (see above). Rows are shaded in
 * parallel (TBB); `progress` (may be empty) receives the fraction of finished rows, increasing,
 * one call at a time (from worker threads). Throws gilab::Error when a per-pixel vector's size
 * is not width x height, or when Embree reports an error.
 */
VplReferenceResult shadeVplsWithShadowRays(const EmbreeScene& scene, const VplReferenceInput& in,
                                           const std::function<void(double)>& progress = {});

}  // namespace gilab::ref
