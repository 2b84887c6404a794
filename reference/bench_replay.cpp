// Raw Embree replay of recorded rays: the floor the path tracer's ray rate is compared with.
#include <algorithm>
#include <chrono>
#include <memory>

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "reference/bench.h"

namespace gilab::ref {
namespace {

enum class Method { Single, Packet8, Packet16, Stream };
constexpr Method kMethods[] = {Method::Single, Method::Packet8, Method::Packet16, Method::Stream};
constexpr unsigned kStreamSize = 256;  // rays per rtcIntersect1M / rtcOccluded1M call

const char* methodName(Method m, bool shadow) {
    switch (m) {
        case Method::Single:
            return shadow ? "rtcOccluded1" : "rtcIntersect1";
        case Method::Packet8:
            return shadow ? "rtcOccluded8" : "rtcIntersect8";
        case Method::Packet16:
            return shadow ? "rtcOccluded16" : "rtcIntersect16";
        case Method::Stream:
            return shadow ? "rtcOccluded1M" : "rtcIntersect1M";
    }
    return "?";
}

void setRay(RTCRay& r, const RecordedRay& in) {
    r.org_x = in.origin.x, r.org_y = in.origin.y, r.org_z = in.origin.z;
    r.dir_x = in.direction.x, r.dir_y = in.direction.y, r.dir_z = in.direction.z;
    r.tnear = in.tNear;
    r.tfar = in.tFar;
    r.time = 0.0f;
    r.mask = ~0u;
    r.id = 0;
    r.flags = 0;
}

void setRayHit(RTCRayHit& rh, const RecordedRay& in) {
    setRay(rh.ray, in);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/** Fills lane i of an SOA packet (RTCRay8/16 or the ray of RTCRayHit8/16). */
template <class RayN>
void setLane(RayN& r, int i, const RecordedRay& in) {
    r.org_x[i] = in.origin.x, r.org_y[i] = in.origin.y, r.org_z[i] = in.origin.z;
    r.dir_x[i] = in.direction.x, r.dir_y[i] = in.direction.y, r.dir_z[i] = in.direction.z;
    r.tnear[i] = in.tNear;
    r.tfar[i] = in.tFar;
    r.time[i] = 0.0f;
    r.mask[i] = ~0u;
    r.id[i] = 0;
    r.flags[i] = 0;
}

template <int N, class RayHitN, class RayN, class Intersect, class Occluded>
uint64_t tracePackets(RTCScene scene, const RecordedRay* rays, size_t count, bool shadow,
                      Intersect intersect, Occluded occluded) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    uint64_t hits = 0;
    for (size_t base = 0; base < count; base += N) {
        const int lanes = int(std::min<size_t>(N, count - base));
        alignas(64) int valid[N];
        if (shadow) {
            RayN packet;
            for (int i = 0; i < N; ++i) {
                valid[i] = i < lanes ? -1 : 0;
                setLane(packet, i, rays[base + size_t(std::min(i, lanes - 1))]);
            }
            occluded(valid, scene, &ctx, &packet);
            for (int i = 0; i < lanes; ++i)
                hits += packet.tfar[i] < 0.0f;
        } else {
            RayHitN packet;
            for (int i = 0; i < N; ++i) {
                valid[i] = i < lanes ? -1 : 0;
                setLane(packet.ray, i, rays[base + size_t(std::min(i, lanes - 1))]);
                packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
                packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
            }
            intersect(valid, scene, &ctx, &packet);
            for (int i = 0; i < lanes; ++i)
                hits += packet.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
        }
    }
    return hits;
}

/** Traces rays [0, count) with one method on the calling thread; returns the hit count. */
uint64_t traceRange(RTCScene scene, const RecordedRay* rays, size_t count, bool shadow, Method m) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    uint64_t hits = 0;
    switch (m) {
        case Method::Single:
            for (size_t i = 0; i < count; ++i) {
                if (shadow) {
                    RTCRay r;
                    setRay(r, rays[i]);
                    rtcOccluded1(scene, &ctx, &r);
                    hits += r.tfar < 0.0f;
                } else {
                    RTCRayHit rh;
                    setRayHit(rh, rays[i]);
                    rtcIntersect1(scene, &ctx, &rh);
                    hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                }
            }
            return hits;
        case Method::Packet8:
            return tracePackets<8, RTCRayHit8, RTCRay8>(scene, rays, count, shadow, rtcIntersect8,
                                                        rtcOccluded8);
        case Method::Packet16:
            return tracePackets<16, RTCRayHit16, RTCRay16>(scene, rays, count, shadow,
                                                           rtcIntersect16, rtcOccluded16);
        case Method::Stream: {
            ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
            RTCRayHit stream[kStreamSize];
            for (size_t base = 0; base < count; base += kStreamSize) {
                const unsigned m = unsigned(std::min<size_t>(kStreamSize, count - base));
                for (unsigned i = 0; i < m; ++i)
                    setRayHit(stream[i], rays[base + i]);
                if (shadow) {  // RTCRayHit starts with its RTCRay: occlusion uses the same buffer
                    rtcOccluded1M(scene, &ctx, &stream[0].ray, m, sizeof(RTCRayHit));
                    for (unsigned i = 0; i < m; ++i)
                        hits += stream[i].ray.tfar < 0.0f;
                } else {
                    rtcIntersect1M(scene, &ctx, stream, m, sizeof(RTCRayHit));
                    for (unsigned i = 0; i < m; ++i)
                        hits += stream[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
                }
            }
            return hits;
        }
    }
    return hits;
}

/** One pass over all rays: on this thread, or in parallel over chunks in `arena`. */
uint64_t tracePass(RTCScene scene, const std::vector<RecordedRay>& rays, bool shadow, Method m,
                   tbb::task_arena* arena) {
    if (!arena) return traceRange(scene, rays.data(), rays.size(), shadow, m);
    tbb::combinable<uint64_t> hits([] { return uint64_t(0); });
    arena->execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 4096),
                          [&](const tbb::blocked_range<size_t>& r) {
                              hits.local() +=
                                  traceRange(scene, rays.data() + r.begin(), r.size(), shadow, m);
                          });
    });
    return hits.combine([](uint64_t a, uint64_t b) { return a + b; });
}

ReplayRate measure(RTCScene scene, const std::vector<RecordedRay>& rays, bool shadow, Method m,
                   int threads, double minSeconds) {
    std::unique_ptr<tbb::task_arena> arena;
    if (threads > 1) arena = std::make_unique<tbb::task_arena>(threads);
    ReplayRate rate;
    rate.method = methodName(m, shadow);
    rate.threads = threads;
    rate.hitsPerPass = tracePass(scene, rays, shadow, m, arena.get());  // warm-up
    const auto start = std::chrono::steady_clock::now();
    do {
        rate.hitsPerPass = tracePass(scene, rays, shadow, m, arena.get());
        rate.rays += rays.size();
        rate.seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    } while (rate.seconds < minSeconds);
    return rate;
}

}  // namespace

ReplayResult replayRays(RTCScene scene, const std::vector<RecordedRay>& rays, int threads,
                        double minSeconds) {
    std::vector<RecordedRay> closest, shadow;
    for (const RecordedRay& r : rays)
        (r.shadow ? shadow : closest).push_back(r);
    ReplayResult result;
    result.closestRays = closest.size();
    result.shadowRays = shadow.size();
    for (bool isShadow : {false, true}) {
        const std::vector<RecordedRay>& set = isShadow ? shadow : closest;
        std::vector<ReplayRate>& out = isShadow ? result.shadow : result.closest;
        if (set.empty()) continue;
        for (int t : {1, threads}) {
            if (t == 1 && threads == 1 && !out.empty()) continue;
            for (Method m : kMethods) {
                out.push_back(measure(scene, set, isShadow, m, t, minSeconds));
                if (out.back().hitsPerPass != out.front().hitsPerPass)
                    result.warnings.push_back(
                        out.back().method + " (" + std::to_string(t) + " threads) found " +
                        std::to_string(out.back().hitsPerPass) + " hits, " + out.front().method +
                        " " + std::to_string(out.front().hitsPerPass) + ", on the same rays");
            }
        }
    }
    return result;
}

}  // namespace gilab::ref
