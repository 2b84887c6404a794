#include "ssvp_propagation.h"

#include <algorithm>
#include <vector>

#include <glm/glm.hpp>

#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/vpl/paraboloid_maps.h"
#include "core/vpl/vpl.h"

namespace gilab {
namespace {

constexpr uint32_t kStateWords = 8;  // mirrors KmeansState

}  // namespace

SsvpPropagation::SsvpPropagation(vk::Context& ctx, const vk::Buffer& vpls,
                                 const vk::Buffer& clusters, ParaboloidMaps& maps,
                                 const std::string& tag) {
    const uint32_t zeros[kStateWords] = {};
    for (int r = 0; r < 2; ++r) {
        m_state[r] = vk::Buffer(
            ctx, kStateWords * 4,
            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
            vk::MemoryUsage::Readback, tag + (r == 0 ? "/kmeans_state" : "/kmeans_state_second"));
        m_state[r].upload(zeros, sizeof(zeros));
    }
    m_members = vk::Buffer(ctx, VkDeviceSize(vpls.size() / sizeof(GpuVpl)) * 16,
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUsage::Readback,
                           tag + "/map_members");
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType buf = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    const VkDescriptorType img = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    m_setLayout = vk::DescriptorSetLayout(ctx,
                                          {{0, buf, 1, cs},
                                           {1, buf, 1, cs},
                                           {2, buf, 1, cs},
                                           {3, img, 1, cs},
                                           {4, img, 1, cs},
                                           {5, img, 1, cs},
                                           {6, buf, 1, cs}},
                                          tag + "/propagation");
    for (int r = 0; r < 2; ++r) {  // the two ranges differ only in their K-means state
        m_set[r] = vk::DescriptorSet(ctx, m_setLayout, 0, tag + "/propagation");
        m_set[r].writeBuffer(0, vpls);
        m_set[r].writeBuffer(1, clusters);
        m_set[r].writeBuffer(2, m_state[r]);
        m_set[r].writeStorageImage(3, maps.position().view());
        m_set[r].writeStorageImage(4, maps.normal().view());
        m_set[r].writeStorageImage(5, maps.albedo().view());
        m_set[r].writeBuffer(6, m_members);
    }
    m_layout = vk::PipelineLayout(ctx, {m_setLayout.handle()}, sizeof(Push));
    m_seed = vk::ComputePipeline(ctx, "ssvp/kmeans_seed.comp", m_layout);
    m_assign = vk::ComputePipeline(ctx, "ssvp/kmeans_assign.comp", m_layout);
    m_update = vk::ComputePipeline(ctx, "ssvp/kmeans_update.comp", m_layout);
    m_second = vk::ComputePipeline(ctx, "ssvp/second_bounce.comp", m_layout);
    m_memberTest = vk::ComputePipeline(ctx, "ssvp/map_members.comp", m_layout);
    m_clusterFlux = vk::ComputePipeline(ctx, "ssvp/cluster_flux.comp", m_layout);
    m_push[0].mapResolution = maps.settings().resolution;
}

void SsvpPropagation::setSettings(const SsvpSettings& s, float sceneDiagonal) {
    m_settings = s;
    const float diagonal = std::max(sceneDiagonal, 1e-20f);
    Push& p = m_push[0];
    p.positionWeight = s.positionWeight;
    p.normalWeight = s.normalWeight;
    p.invDiagonal = 1.0f / diagonal;
    p.eyeOffset = s.centroidOffset * diagonal;
    p.count = s.firstBounceVpls;
    p.clusterCount = s.clusters;
    p.metric = s.literalMetric ? 1u : 0u;
    // `seed` moves the K-means start (which VPLs seed the clusters) with the VPL pattern; the
    // golden-ratio step keeps nearby seeds' starts apart; seed 0 leaves kmeans_seed as it was.
    p.seed = s.kmeansSeed + s.seed * 0x9E3779B9u;
    p.secondCount = s.secondCount();
    p.perCluster = std::max(s.perCluster(), 1u);
    p.paperWeights = s.paperWeights ? 1u : 0u;
    p.secondVisibility = s.secondVisibility == SecondBounceVisibility::Cluster ? 1u : 0u;
    p.eyeAtVpl = s.eyeAtNearestVpl ? 1u : 0u;
    p.reassign = s.reassignMembers ? 1u : 0u;
    p.biasTexels = s.visibilityBiasTexels;
    p.vplBase = 0;
    p.clusterBase = 0;
    // The second range: the same K-means rules over the second-bounce VPLs (own_maps).
    Push& q = m_push[1];
    q = p;
    q.count = s.ownMapClusters() > 0 ? s.secondCount() : 0u;
    q.clusterCount = s.ownMapClusters();
    q.seed = p.seed + 7919u;
    q.secondCount = 0;
    q.vplBase = s.firstBounceVpls;
    q.clusterBase = s.clusters;
}

const SsvpPropagation::Push& SsvpPropagation::bind(VkCommandBuffer cmd,
                                                   const vk::ComputePipeline& pipeline,
                                                   SsvpRange range) {
    const int r = int(range);
    pipeline.bind(cmd);
    VkDescriptorSet set = m_set[r].handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set, 0,
                            nullptr);
    m_layout.push(cmd, m_push[r]);
    return m_push[r];
}

void SsvpPropagation::recordClustering(VkCommandBuffer cmd, SsvpRange range) {
    const Push& p = m_push[int(range)];
    if (p.count == 0 || p.clusterCount == 0) return;
    const VkBuffer state = m_state[int(range)].handle();
    // changed, iterations, converged, (seeded kept), reseeded: a new frame's K-means.
    vkCmdFillBuffer(cmd, state, 0, 12, 0);
    vkCmdFillBuffer(cmd, state, 16, 4, 0);
    vk::memoryBarrier(cmd);
    bind(cmd, m_seed, range);
    vkCmdDispatch(cmd, 1, 1, 1);
    vk::memoryBarrier(cmd);
    Push push = p;
    for (uint32_t it = 0; it < m_settings.kmeansIterations; ++it) {
        push.iteration = it;
        bind(cmd, m_assign, range);
        m_layout.push(cmd, push);
        vk::dispatch1D(cmd, push.count, 64);
        vk::memoryBarrier(cmd);
        bind(cmd, m_update, range);
        m_layout.push(cmd, push);
        vkCmdDispatch(cmd, 1, 1, 1);
        vk::memoryBarrier(cmd);
    }
    vk::hostReadBarrier(cmd);
}

void SsvpPropagation::recordMembers(VkCommandBuffer cmd, SsvpRange range) {
    const Push& p = m_push[int(range)];
    if (p.count == 0 || p.clusterCount == 0) return;
    bind(cmd, m_memberTest, range);
    vk::dispatch1D(cmd, p.count, 64);
    vk::memoryBarrier(cmd);
    if (p.reassign != 0u) {
        bind(cmd, m_clusterFlux, range);
        vkCmdDispatch(cmd, 1, 1, 1);
        vk::memoryBarrier(cmd);
    }
    vk::hostReadBarrier(cmd);
}

void SsvpPropagation::recordSecondBounce(VkCommandBuffer cmd) {
    const Push& p = bind(cmd, m_second, SsvpRange::First);
    if (p.secondCount == 0) return;
    vk::dispatch1D(cmd, p.secondCount, 64);
    vk::memoryBarrier(cmd);
}

SsvpMemberStats SsvpPropagation::readMemberStats(SsvpRange range) {
    const Push& p = m_push[int(range)];
    SsvpMemberStats s;
    if (p.count == 0) return s;
    std::vector<glm::vec4> m(p.vplBase + p.count);
    m_members.download(m.data(), VkDeviceSize(m.size()) * 16);
    double flux = 0.0, seen = 0.0, after = 0.0, moved = 0.0;
    for (size_t i = p.vplBase; i < m.size(); ++i) {
        const glm::vec4& v = m[i];
        flux += v.x;
        seen += v.x * v.y;
        after += v.x * v.z;
        moved += v.x * v.w;
    }
    if (flux > 0.0) {
        s.seenPercent = 100.0 * seen / flux;
        s.seenAfterPercent = 100.0 * after / flux;
        s.movedPercent = 100.0 * moved / flux;
    }
    return s;
}

SsvpKmeansState SsvpPropagation::readState(SsvpRange range) {
    uint32_t words[kStateWords] = {};
    m_state[int(range)].download(words, sizeof(words));
    return {words[1], words[2] != 0, words[4], words[5], words[6]};
}

}  // namespace gilab
