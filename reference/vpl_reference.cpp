#include "reference/vpl_reference.h"

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <mutex>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/util/error.h"
#include "core/vpl/vpl_math.h"

namespace gilab::ref {
namespace {

constexpr uint32_t kTile = 4;  // 4 x 4 pixels: one 16-ray packet per VPL
constexpr uint32_t kLanes = kTile * kTile;
constexpr float kOffsetRelative = 1e-4f;  // of the scene diagonal
constexpr float kOffsetUlps = 16.0f;      // x FLT_EPSILON x the largest coordinate

bool finite3(const glm::vec4& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/** The unit vector of v, or 0 when v has no length. */
glm::vec3 unitOrZero(const glm::vec3& v) {
    const float len = glm::length(v);
    return len > 0.0f ? v / len : glm::vec3(0.0f);
}

/** A covered pixel, ready to shade. */
struct Receiver {
    glm::vec3 p{0.0f}, n{0.0f};
    glm::vec3 origin{0.0f};  // shadow-ray origin p + unit(n) eps_p
    bool active = false;
};

/** A valid VPL, ready to shade. */
struct Light {
    glm::vec3 p{0.0f}, n{0.0f};
    glm::vec3 target{0.0f};  // shadow-ray end v.pos + unit(n_v) eps_v
    glm::vec3 flux{0.0f};    // flux x scale[bounce]
};

float sceneDiagonal(const EmbreeScene& scene) {
    RTCBounds b;
    rtcGetSceneBounds(scene.handle(), &b);
    scene.checkError("reading the scene bounds");
    const glm::vec3 lo(b.lower_x, b.lower_y, b.lower_z), hi(b.upper_x, b.upper_y, b.upper_z);
    if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return 0.0f;  // empty scene
    const float d = glm::length(hi - lo);
    return std::isfinite(d) ? d : 0.0f;
}

void checkSize(size_t size, size_t expected, const char* name, const VplReferenceInput& in) {
    if (size == expected) return;
    throw Error("VPL reference: input '" + std::string(name) + "' has " + std::to_string(size) +
                " entries, expected width x height = " + std::to_string(in.width) + " x " +
                std::to_string(in.height) + " = " + std::to_string(expected));
}

/** Shades the 4 x 4 tile at (x0, y0); returns the shadow rays traced. */
uint64_t shadeTile(const EmbreeScene& scene, const VplReferenceInput& in,
                   const std::vector<Light>& lights, const Receiver* receivers, uint32_t x0,
                   uint32_t y0, VplReferenceResult& out) {
    const uint32_t w = in.width;
    const uint32_t tw = std::min(kTile, in.width - x0), th = std::min(kTile, in.height - y0);
    const Receiver* lane[kLanes] = {};
    size_t pixel[kLanes] = {};
    bool any = false;
    for (uint32_t j = 0; j < th; ++j)
        for (uint32_t i = 0; i < tw; ++i) {
            const size_t idx = size_t(y0 + j) * w + (x0 + i);
            if (!receivers[idx].active) continue;
            lane[j * kTile + i] = &receivers[idx];
            pixel[j * kTile + i] = idx;
            any = true;
        }
    if (!any) return 0;

    const float minD2 = in.clampDistance * in.clampDistance;
    glm::dvec3 exact[kLanes], unshadowed[kLanes];
    for (uint32_t k = 0; k < kLanes; ++k)
        exact[k] = unshadowed[k] = glm::dvec3(0.0);

    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    alignas(64) RTCRay16 packet;
    alignas(64) int valid[kLanes];
    if (in.packets) {
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        for (uint32_t k = 0; k < kLanes; ++k) {
            packet.org_x[k] = packet.org_y[k] = packet.org_z[k] = 0.0f;
            packet.dir_x[k] = packet.dir_y[k] = 0.0f;
            packet.dir_z[k] = 1.0f;
            packet.tnear[k] = 0.0f;
            packet.tfar[k] = 1.0f;
            packet.time[k] = 0.0f;
            packet.mask[k] = ~0u;
            packet.id[k] = k;
            packet.flags[k] = 0;
        }
    }

    uint64_t rays = 0;
    glm::vec3 term[kLanes];
    for (const Light& v : lights) {
        int traced = 0;
        for (uint32_t k = 0; k < kLanes; ++k) {
            valid[k] = 0;
            const Receiver* r = lane[k];
            if (!r) continue;
            // vpl_gather.comp, per VPL (same float operations and order)
            const glm::vec3 d = v.p - r->p;
            const float d2 = glm::dot(d, d);
            if (!(d2 > 1e-20f)) continue;  // a VPL on the receiver: no direction, no light
            const glm::vec3 l = d * (1.0f / std::sqrt(d2));
            const float g =
                std::max(glm::dot(r->n, l), 0.0f) * std::max(glm::dot(v.n, -l), 0.0f) / vpl::kPi;
            if (!(g > 0.0f)) continue;
            const glm::vec3 phi = v.flux * g;
            term[k] = phi / std::max(d2, minD2);
            unshadowed[k] += glm::dvec3(term[k]);

            const glm::vec3 seg = v.target - r->origin;
            if (!(glm::dot(seg, seg) > 0.0f)) {  // both ends offset onto one point: nothing between
                exact[k] += glm::dvec3(term[k]);
                continue;
            }
            ++rays;
            if (in.packets) {
                valid[k] = -1;
                packet.org_x[k] = r->origin.x;
                packet.org_y[k] = r->origin.y;
                packet.org_z[k] = r->origin.z;
                packet.dir_x[k] = seg.x;
                packet.dir_y[k] = seg.y;
                packet.dir_z[k] = seg.z;
                packet.tfar[k] = 1.0f;
                ++traced;
            } else {
                RTCRay ray;
                ray.org_x = r->origin.x;
                ray.org_y = r->origin.y;
                ray.org_z = r->origin.z;
                ray.tnear = 0.0f;
                ray.dir_x = seg.x;
                ray.dir_y = seg.y;
                ray.dir_z = seg.z;
                ray.time = 0.0f;
                ray.tfar = 1.0f;
                ray.mask = ~0u;
                ray.id = k;
                ray.flags = 0;
                rtcOccluded1(scene.handle(), &context, &ray);
                if (ray.tfar >= 0.0f) exact[k] += glm::dvec3(term[k]);  // tfar = -inf on a hit
            }
        }
        if (traced == 0) continue;
        rtcOccluded16(valid, scene.handle(), &context, &packet);
        for (uint32_t k = 0; k < kLanes; ++k)
            if (valid[k] && packet.tfar[k] >= 0.0f) exact[k] += glm::dvec3(term[k]);
    }

    // vpl_blur.comp: outgoing radiance albedo / pi x E
    for (uint32_t k = 0; k < kLanes; ++k) {
        if (!lane[k]) continue;
        const size_t idx = pixel[k];
        const glm::vec3 rho = glm::vec3(in.albedo[idx]) / vpl::kPi;
        out.exact[idx] = glm::vec4(rho * glm::vec3(exact[k]), 1.0f);
        out.unshadowed[idx] = glm::vec4(rho * glm::vec3(unshadowed[k]), 1.0f);
    }
    return rays;
}

}  // namespace

float vplShadowRayOffset(const glm::vec3& q, float sceneDiagonal) {
    const float magnitude = std::max({std::abs(q.x), std::abs(q.y), std::abs(q.z)});
    return std::max(kOffsetRelative * sceneDiagonal, kOffsetUlps * FLT_EPSILON * magnitude);
}

VplReferenceResult shadeVplsWithShadowRays(const EmbreeScene& scene, const VplReferenceInput& in,
                                           const std::function<void(double)>& progress) {
    const auto start = std::chrono::steady_clock::now();
    const size_t count = size_t(in.width) * size_t(in.height);
    checkSize(in.position.size(), count, "position", in);
    checkSize(in.normal.size(), count, "normal", in);
    checkSize(in.albedo.size(), count, "albedo", in);
    if (!std::isfinite(in.clampDistance) || in.clampDistance < 0.0f)
        throw Error("VPL reference: clampDistance must be finite and >= 0, got " +
                    std::to_string(in.clampDistance));
    if (!std::isfinite(in.bounceScale.x) || !std::isfinite(in.bounceScale.y))
        throw Error("VPL reference: bounceScale must be finite");

    VplReferenceResult out;
    out.exact.assign(count, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    out.unshadowed.assign(count, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    const float diagonal = sceneDiagonal(scene);

    std::vector<Light> lights;
    lights.reserve(in.vpls.size());
    for (const GpuVpl& v : in.vpls) {
        if (!(v.position.w >= 0.5f)) continue;
        if (!finite3(v.position) || !finite3(v.normal) || !finite3(v.flux) ||
            !std::isfinite(v.flux.w)) {
            ++out.invalidVpls;
            continue;
        }
        Light l;
        l.p = glm::vec3(v.position);
        l.n = glm::vec3(v.normal);
        l.target = l.p + unitOrZero(l.n) * vplShadowRayOffset(l.p, diagonal);
        l.flux = glm::vec3(v.flux) * (v.flux.w > 1.5f ? in.bounceScale.y : in.bounceScale.x);
        lights.push_back(l);
    }

    std::vector<Receiver> receivers(count);
    for (size_t i = 0; i < count; ++i) {
        if (!(in.position[i].w > 0.5f)) continue;
        if (!finite3(in.position[i]) || !finite3(in.normal[i]) || !finite3(in.albedo[i])) {
            ++out.invalidPixels;
            continue;
        }
        Receiver& r = receivers[i];
        r.p = glm::vec3(in.position[i]);
        r.n = glm::vec3(in.normal[i]);
        r.origin = r.p + unitOrZero(r.n) * vplShadowRayOffset(r.p, diagonal);
        r.active = true;
    }

    // Bands of kTile rows in parallel; each pixel's sum runs over the VPLs in index order
    const uint32_t bands = (in.height + kTile - 1) / kTile;
    std::atomic<uint64_t> rays{0};
    std::mutex progressMutex;
    uint32_t rowsDone = 0;
    tbb::parallel_for(
        tbb::blocked_range<uint32_t>(0, bands, 1), [&](const tbb::blocked_range<uint32_t>& range) {
            for (uint32_t b = range.begin(); b != range.end(); ++b) {
                const uint32_t y0 = b * kTile;
                uint64_t bandRays = 0;
                for (uint32_t x0 = 0; x0 < in.width; x0 += kTile)
                    bandRays += shadeTile(scene, in, lights, receivers.data(), x0, y0, out);
                rays += bandRays;
                if (progress) {
                    std::lock_guard<std::mutex> lock(progressMutex);
                    rowsDone += std::min(kTile, in.height - y0);
                    progress(double(rowsDone) / double(in.height));
                }
            }
        });
    scene.checkError("tracing VPL shadow rays");

    out.rays = double(rays.load());
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace gilab::ref
