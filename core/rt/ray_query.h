#pragma once
/**
 * Batch ray queries on the GPU ray tracer: uploads rays, traces them with
 * shaders/common/rt_query.comp (closest hit or occlusion) and reads the hits back. For the
 * validation against Embree (`gilab bench rt`, tests/rt_test.cpp) and for any CPU-side code that
 * wants GPU rays; passes that trace inside their own shaders include rt_trace.glsl directly.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/pipeline.h"

namespace gilab::vk {
class Context;
}

namespace gilab::rt {

class GpuBvh;

struct QueryRay {
    glm::vec3 origin{0.0f};
    float tMin = 0.0f;
    glm::vec3 direction{0.0f, 0.0f, 1.0f};  // need not be unit: t is in its units
    float tMax = 1e30f;
};
static_assert(sizeof(QueryRay) == 32);

inline constexpr uint32_t kNoHit = 0xffffffffu;

struct QueryHit {
    float t = -1.0f;             // closest: distance; occlusion: 1 = occluded, 0 = free
    uint32_t triangle = kNoHit;  // scene triangle id (closest hits only)
    glm::vec2 bary{0.0f};        // (b1, b2): p = p0 + b1 (p1 - p0) + b2 (p2 - p0)
};
static_assert(sizeof(QueryHit) == 16);

enum class QueryMode : uint32_t { Closest = 0, Occluded = 1 };

class RayQuery {
public:
    RayQuery(vk::Context& ctx, const GpuBvh& bvh);
    RayQuery(const RayQuery&) = delete;
    RayQuery& operator=(const RayQuery&) = delete;

    /** Traces every ray (in batches that fit the buffers), blocking; returns one hit per ray.
     *  gpuSeconds (optional) receives the summed GPU time of the trace dispatches. */
    std::vector<QueryHit> trace(const std::vector<QueryRay>& rays, QueryMode mode,
                                double* gpuSeconds = nullptr);

private:
    void ensureCapacity(size_t rays);

    vk::Context& m_ctx;
    const GpuBvh& m_bvh;
    size_t m_capacity = 0;
    vk::Buffer m_rays;
    vk::Buffer m_hits;
    vk::DescriptorSetLayout m_setLayout;
    vk::DescriptorSet m_set;
    vk::PipelineLayout m_layout;
    vk::ComputePipeline m_pipeline;
};

}  // namespace gilab::rt
