#include "techniques/ssvp/ssvp_propagation.h"

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
    m_state = vk::Buffer(ctx, kStateWords * 4,
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                         vk::MemoryUsage::Readback, tag + "/kmeans_state");
    const uint32_t zeros[kStateWords] = {};
    m_state.upload(zeros, sizeof(zeros));
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
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, tag + "/propagation");
    m_set.writeBuffer(0, vpls);
    m_set.writeBuffer(1, clusters);
    m_set.writeBuffer(2, m_state);
    m_set.writeStorageImage(3, maps.position().view());
    m_set.writeStorageImage(4, maps.normal().view());
    m_set.writeStorageImage(5, maps.albedo().view());
    m_set.writeBuffer(6, m_members);
    m_layout = vk::PipelineLayout(ctx, {m_setLayout.handle()}, sizeof(Push));
    m_seed = vk::ComputePipeline(ctx, "ssvp/kmeans_seed.comp", m_layout);
    m_assign = vk::ComputePipeline(ctx, "ssvp/kmeans_assign.comp", m_layout);
    m_update = vk::ComputePipeline(ctx, "ssvp/kmeans_update.comp", m_layout);
    m_second = vk::ComputePipeline(ctx, "ssvp/second_bounce.comp", m_layout);
    m_memberTest = vk::ComputePipeline(ctx, "ssvp/map_members.comp", m_layout);
    m_clusterFlux = vk::ComputePipeline(ctx, "ssvp/cluster_flux.comp", m_layout);
    m_push.mapResolution = maps.settings().resolution;
}

void SsvpPropagation::setSettings(const SsvpSettings& s, float sceneDiagonal) {
    m_settings = s;
    const float diagonal = std::max(sceneDiagonal, 1e-20f);
    m_push.positionWeight = s.positionWeight;
    m_push.normalWeight = s.normalWeight;
    m_push.invDiagonal = 1.0f / diagonal;
    m_push.eyeOffset = s.centroidOffset * diagonal;
    m_push.count = s.firstBounceVpls;
    m_push.clusterCount = s.clusters;
    m_push.metric = s.literalMetric ? 1u : 0u;
    m_push.seed = s.kmeansSeed;
    m_push.secondCount = s.bounces >= 2 ? s.secondBounceVpls : 0u;
    m_push.perCluster = std::max(s.perCluster(), 1u);
    m_push.paperWeights = s.paperWeights ? 1u : 0u;
    m_push.secondVisibility = s.secondBounceVisibility ? 1u : 0u;
    m_push.eyeAtVpl = s.eyeAtNearestVpl ? 1u : 0u;
    m_push.reassign = s.reassignMembers ? 1u : 0u;
    m_push.biasTexels = s.visibilityBiasTexels;
}

void SsvpPropagation::bind(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline) {
    pipeline.bind(cmd);
    VkDescriptorSet set = m_set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set, 0,
                            nullptr);
}

void SsvpPropagation::recordClustering(VkCommandBuffer cmd) {
    // changed, iterations, converged, (seeded kept), reseeded: a new frame's K-means.
    vkCmdFillBuffer(cmd, m_state.handle(), 0, 12, 0);
    vkCmdFillBuffer(cmd, m_state.handle(), 16, 4, 0);
    vk::memoryBarrier(cmd);
    Push push = m_push;
    bind(cmd, m_seed);
    m_layout.push(cmd, push);
    vkCmdDispatch(cmd, 1, 1, 1);
    vk::memoryBarrier(cmd);
    for (uint32_t it = 0; it < m_settings.kmeansIterations; ++it) {
        push.iteration = it;
        bind(cmd, m_assign);
        m_layout.push(cmd, push);
        vk::dispatch1D(cmd, m_settings.firstBounceVpls, 64);
        vk::memoryBarrier(cmd);
        bind(cmd, m_update);
        m_layout.push(cmd, push);
        vkCmdDispatch(cmd, 1, 1, 1);
        vk::memoryBarrier(cmd);
    }
    vk::hostReadBarrier(cmd);
}

void SsvpPropagation::recordMembers(VkCommandBuffer cmd) {
    bind(cmd, m_memberTest);
    m_layout.push(cmd, m_push);
    vk::dispatch1D(cmd, m_push.count, 64);
    vk::memoryBarrier(cmd);
    if (m_push.reassign != 0u) {
        bind(cmd, m_clusterFlux);
        m_layout.push(cmd, m_push);
        vkCmdDispatch(cmd, 1, 1, 1);
        vk::memoryBarrier(cmd);
    }
    vk::hostReadBarrier(cmd);
}

void SsvpPropagation::recordSecondBounce(VkCommandBuffer cmd) {
    if (m_push.secondCount == 0) return;
    bind(cmd, m_second);
    m_layout.push(cmd, m_push);
    vk::dispatch1D(cmd, m_push.secondCount, 64);
    vk::memoryBarrier(cmd);
}

SsvpMemberStats SsvpPropagation::readMemberStats() {
    std::vector<glm::vec4> m(m_push.count);
    m_members.download(m.data(), VkDeviceSize(m.size()) * 16);
    double flux = 0.0, seen = 0.0, after = 0.0, moved = 0.0;
    for (const glm::vec4& v : m) {
        flux += v.x;
        seen += v.x * v.y;
        after += v.x * v.z;
        moved += v.x * v.w;
    }
    SsvpMemberStats s;
    if (flux > 0.0) {
        s.seenPercent = 100.0 * seen / flux;
        s.seenAfterPercent = 100.0 * after / flux;
        s.movedPercent = 100.0 * moved / flux;
    }
    return s;
}

SsvpKmeansState SsvpPropagation::readState() {
    uint32_t words[kStateWords] = {};
    m_state.download(words, sizeof(words));
    return {words[1], words[2] != 0, words[4], words[5], words[6]};
}

}  // namespace gilab
