#include "ray_query.h"

#include <algorithm>

#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/vk/timer.h"
#include "gpu_bvh.h"

namespace gilab::rt {
namespace {

constexpr size_t kBatch = size_t(1) << 18;  // rays per dispatch (8 MiB of rays)

struct Push {
    uint32_t count;
    uint32_t mode;
};

}  // namespace

RayQuery::RayQuery(vk::Context& ctx, const GpuBvh& bvh) : m_ctx(ctx), m_bvh(bvh) {
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    std::vector<vk::DescriptorBinding> bindings = {
        {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, cs},
    };
    GpuBvh::addLayoutBindings(bindings, 2, cs);
    m_setLayout = vk::DescriptorSetLayout(ctx, bindings, "rt/query");
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, "rt/query");
    bvh.writeDescriptors(m_set, 2);
    m_layout = vk::PipelineLayout(ctx, {m_setLayout.handle()}, sizeof(Push), cs);
    m_pipeline = vk::ComputePipeline(ctx, "common/rt_query.comp", m_layout);
}

void RayQuery::ensureCapacity(size_t rays) {
    if (rays <= m_capacity) return;
    m_capacity = rays;
    m_rays = vk::Buffer(m_ctx, rays * sizeof(QueryRay), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                        vk::MemoryUsage::Upload, "rt/query_rays");
    m_hits = vk::Buffer(m_ctx, rays * sizeof(QueryHit), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                        vk::MemoryUsage::Readback, "rt/query_hits");
    m_set.writeBuffer(0, m_rays);
    m_set.writeBuffer(1, m_hits);
}

std::vector<QueryHit> RayQuery::trace(const std::vector<QueryRay>& rays, QueryMode mode,
                                      double* gpuSeconds) {
    std::vector<QueryHit> hits(rays.size());
    if (gpuSeconds) *gpuSeconds = 0.0;
    if (rays.empty()) return hits;
    ensureCapacity(std::min(rays.size(), kBatch));
    vk::GpuTimer timer(m_ctx, 4);
    for (size_t first = 0; first < rays.size(); first += kBatch) {
        const size_t count = std::min(kBatch, rays.size() - first);
        m_rays.upload(rays.data() + first, count * sizeof(QueryRay));
        m_ctx.submitAndWait([&](VkCommandBuffer cmd) {
            timer.reset(cmd);
            timer.begin(cmd, "rt/query");
            m_pipeline.bind(cmd);
            VkDescriptorSet set = m_set.handle();
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1,
                                    &set, 0, nullptr);
            m_layout.push(cmd, Push{uint32_t(count), uint32_t(mode)});
            vk::dispatch1D(cmd, uint32_t(count), 64);
            timer.end(cmd);
            vk::memoryBarrier(cmd);
        });
        if (gpuSeconds && timer.supported())
            for (const vk::PassTime& t : timer.resolve())
                *gpuSeconds += t.gpuMs * 1e-3;
        m_hits.download(hits.data() + first, count * sizeof(QueryHit));
    }
    return hits;
}

}  // namespace gilab::rt
