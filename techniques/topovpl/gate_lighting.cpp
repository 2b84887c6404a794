#include "gate_lighting.h"

#include <algorithm>

#include "core/passes/gbuffer.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/vpl/vpl.h"
#include "pixel_clusters.h"

namespace gilab::topo {
namespace {

constexpr VkDescriptorType kImage = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
constexpr VkDescriptorType kBuffer = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
constexpr uint32_t kGroup = 8;  // il.comp's 8 x 8 workgroups
constexpr uint32_t kNone = 0xFFFFFFFFu;

struct GpuTopoGeoCluster {
    glm::vec4 lo, hi;
    glm::uvec4 info;
};

uint32_t groupCount(uint32_t w, uint32_t h) {
    return ((w + kGroup - 1) / kGroup) * ((h + kGroup - 1) / kGroup);
}

}  // namespace

GateLighting::Stage GateLighting::makeStage(vk::Context& ctx,
                                            const std::vector<VkDescriptorType>& types,
                                            uint32_t pushBytes, const std::string& shader,
                                            const std::string& tag) {
    std::vector<vk::DescriptorBinding> bindings;
    for (uint32_t b = 0; b < types.size(); ++b)
        bindings.push_back({b, types[b], 1, VK_SHADER_STAGE_COMPUTE_BIT});
    Stage s;
    s.setLayout = vk::DescriptorSetLayout(ctx, bindings, tag);
    s.set = vk::DescriptorSet(ctx, s.setLayout, 0, tag);
    s.layout = vk::PipelineLayout(ctx, {s.setLayout.handle()}, pushBytes);
    s.pipeline = vk::ComputePipeline(ctx, shader, s.layout);
    return s;
}

void GateLighting::Stage::bind(VkCommandBuffer cmd) const {
    pipeline.bind(cmd);
    VkDescriptorSet h = set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout.handle(), 0, 1, &h, 0,
                            nullptr);
}

GateLighting::GateLighting(vk::Context& ctx, GBuffer& gbuffer, PixelClusters& pixels,
                           vk::Buffer& vpls, uint32_t vplCount, const GateTable& table,
                           uint64_t entryCapacity, const std::string& tag)
    : m_width(gbuffer.width),
      m_height(gbuffer.height),
      m_vplCount(vplCount),
      m_clusterCount(table.clusterCount),
      m_capacity(entryCapacity),
      m_grid(pixels.grid()),
      m_vpls(vpls) {
    if (table.clusterStart.size() != size_t(table.clusterCount) + 1)
        throw Error(tag + ": the gate table has " + std::to_string(table.clusterStart.size()) +
                    " cluster offsets for " + std::to_string(table.clusterCount) + " clusters");
    const VkDeviceSize range = ctx.properties().limits.maxStorageBufferRange;
    m_capacity = std::min<uint64_t>({m_capacity, range / 8, kNone});
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    auto buffer = [&](VkDeviceSize bytes, const std::string& name, VkBufferUsageFlags extra = 0) {
        return vk::Buffer(ctx, std::max<VkDeviceSize>(bytes, 16), storage | extra,
                          vk::MemoryUsage::DeviceLocal, tag + "/" + name);
    };
    const uint64_t pixelsCount = uint64_t(m_width) * m_height;
    m_vplClusters = buffer(VkDeviceSize(vplCount) * 4, "vpl_clusters");
    m_gates = buffer(VkDeviceSize(table.gates.size()) * sizeof(GpuGate), "gates");
    m_clusterStart = buffer(VkDeviceSize(table.clusterStart.size()) * 4, "cluster_gate_start");
    m_clusterGates = buffer(VkDeviceSize(table.clusterGates.size()) * 4, "cluster_gates");
    // At most one geometry cluster per covered pixel: the IUGC can never overflow.
    m_geo = buffer(pixelsCount * sizeof(GpuTopoGeoCluster), "geometry_clusters");
    m_counts = buffer(pixelsCount * 4, "la_counts");
    m_offsets = buffer(pixelsCount * 4, "la_offsets");
    m_entries = buffer(m_capacity * 8, "la_entries");
    m_state = buffer(32, "state", VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    m_partials = buffer(VkDeviceSize(groupCount(m_width, m_height)) * 16, "clamp_partials");
    m_sharePartials = buffer(VkDeviceSize(groupCount(m_width, m_height)) * 16, "share_partials");
    m_gates.uploadVector(table.gates);
    m_clusterStart.uploadVector(table.clusterStart);
    m_clusterGates.uploadVector(table.clusterGates);
    m_geoImage = vk::Image(ctx, vk::imageDesc2D(m_width, m_height, VK_FORMAT_R32_UINT,
                                                VK_IMAGE_USAGE_STORAGE_BIT, tag + "/geo_clusters"));
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
        m_geoImage.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
        for (vk::Buffer* b : {&m_vplClusters, &m_geo, &m_counts, &m_offsets, &m_state, &m_partials,
                              &m_sharePartials})
            vkCmdFillBuffer(cmd, b->handle(), 0, VK_WHOLE_SIZE, 0);
    });

    m_vplStage = makeStage(ctx, {kBuffer, kBuffer, kBuffer}, sizeof(GpuVoxelGrid) + 16,
                           "topovpl/vpl_cluster.comp", tag + "/vpl_clusters");
    m_vplStage.set.writeBuffer(0, vpls);
    m_vplStage.set.writeBuffer(1, pixels.voxelClusters());
    m_vplStage.set.writeBuffer(2, m_vplClusters);

    m_iugc = makeStage(ctx, {kImage, kImage, kImage, kBuffer, kBuffer}, 40, "topovpl/iugc.comp",
                       tag + "/iugc");
    m_iugc.set.writeStorageImage(0, gbuffer.position.view());
    m_iugc.set.writeStorageImage(1, pixels.clusters().view());
    m_iugc.set.writeStorageImage(2, m_geoImage.view());
    m_iugc.set.writeBuffer(3, m_geo);
    m_iugc.set.writeBuffer(4, m_state);

    m_laArgs = makeStage(ctx, {kBuffer}, 0, "topovpl/la_args.comp", tag + "/la_args");
    m_laArgs.set.writeBuffer(0, m_state);

    m_laAssign = makeStage(ctx, std::vector<VkDescriptorType>(10, kBuffer), 24,
                           "topovpl/la_assign.comp", tag + "/la");
    const vk::Buffer* la[] = {&vpls,  &m_vplClusters, &m_gates,   &m_clusterStart, &m_clusterGates,
                              &m_geo, &m_counts,      &m_offsets, &m_entries,      &m_state};
    for (uint32_t b = 0; b < 10; ++b)
        m_laAssign.set.writeBuffer(b, *la[b]);

    m_laScan =
        makeStage(ctx, {kBuffer, kBuffer, kBuffer}, 0, "topovpl/la_scan.comp", tag + "/la_scan");
    m_laScan.set.writeBuffer(0, m_counts);
    m_laScan.set.writeBuffer(1, m_offsets);
    m_laScan.set.writeBuffer(2, m_state);

    m_il = makeStage(ctx,
                     {kImage, kImage, kImage, kImage, kBuffer, kBuffer, kBuffer, kBuffer, kBuffer,
                      kImage, kBuffer},
                     8, "topovpl/il.comp", tag + "/il");
    m_il.set.writeStorageImage(0, gbuffer.position.view());
    m_il.set.writeStorageImage(1, gbuffer.normal.view());
    m_il.set.writeStorageImage(2, gbuffer.albedo.view());
    m_il.set.writeStorageImage(3, m_geoImage.view());
    m_il.set.writeBuffer(4, vpls);
    m_il.set.writeBuffer(5, m_gates);
    m_il.set.writeBuffer(6, m_counts);
    m_il.set.writeBuffer(7, m_offsets);
    m_il.set.writeBuffer(8, m_entries);
    m_il.set.writeBuffer(10, m_partials);

    m_share = makeStage(ctx, {kImage, kImage, kImage, kImage, kBuffer, kBuffer, kBuffer}, 8,
                        "topovpl/same_cluster_share.comp", tag + "/same_cluster_share");
    m_share.set.writeStorageImage(0, gbuffer.position.view());
    m_share.set.writeStorageImage(1, gbuffer.normal.view());
    m_share.set.writeStorageImage(2, gbuffer.albedo.view());
    m_share.set.writeStorageImage(3, pixels.clusters().view());
    m_share.set.writeBuffer(4, vpls);
    m_share.set.writeBuffer(5, m_vplClusters);
    m_share.set.writeBuffer(6, m_sharePartials);
}

void GateLighting::recordSameClusterShare(VkCommandBuffer cmd, float clampDistance) {
    m_share.bind(cmd);
    const struct {
        float clamp;
        uint32_t vplCount;
    } push{clampDistance, m_vplCount};
    m_share.layout.push(cmd, push);
    vk::dispatch2D(cmd, m_width, m_height, kGroup, kGroup);
    vk::memoryBarrier(cmd);
    vk::hostReadBarrier(cmd);
}

void GateLighting::updateGates(const std::vector<GpuGate>& gates) {
    if (gates.size() * sizeof(GpuGate) > m_gates.size())
        throw Error("topovpl: updateGates with more gates than at set-up");
    m_gates.uploadVector(gates);
}

void GateLighting::recordVplClusters(VkCommandBuffer cmd) {
    m_vplStage.bind(cmd);
    const struct {
        GpuVoxelGrid grid;
        uint32_t count, pad[3];
    } push{m_grid.gpu(), m_vplCount, {0, 0, 0}};
    m_vplStage.layout.push(cmd, push);
    vk::dispatch1D(cmd, m_vplCount, 64);
    vk::memoryBarrier(cmd);
}

void GateLighting::recordIugc(VkCommandBuffer cmd, const glm::vec3& eye, const glm::vec3& forward,
                              float zNear, float zFar, uint32_t tile, uint32_t slices) {
    vkCmdFillBuffer(cmd, m_state.handle(), 0, 16, 0);  // cluster count, total
    vk::memoryBarrier(cmd);
    m_iugc.bind(cmd);
    const struct {
        glm::vec4 eye, forward;
        uint32_t tile, slices;
    } push{glm::vec4(eye, zNear), glm::vec4(forward, std::max(zFar, zNear * 1.001f)), tile, slices};
    m_iugc.layout.push(cmd, push);
    vkCmdDispatch(cmd, (m_width + tile - 1) / tile, (m_height + tile - 1) / tile, 1);
    vk::memoryBarrier(cmd);
}

void GateLighting::recordLa(VkCommandBuffer cmd, LaMode mode, bool farClusterOnly) {
    m_laArgs.bind(cmd);
    vkCmdDispatch(cmd, 1, 1, 1);
    vk::memoryBarrier(cmd);
    m_laAssign.bind(cmd);
    auto assign = [&](uint32_t fill) {
        const struct {
            uint32_t vplCount, fill, mode, farOnly, capacity, clusterCount;
        } push{m_vplCount,           fill,          uint32_t(mode), farClusterOnly ? 1u : 0u,
               uint32_t(m_capacity), m_clusterCount};
        m_laAssign.layout.push(cmd, push);
        vkCmdDispatchIndirect(cmd, m_state.handle(), 16);
        vk::memoryBarrier(cmd);
    };
    assign(0);
    m_laScan.bind(cmd);
    vkCmdDispatch(cmd, 1, 1, 1);
    vk::memoryBarrier(cmd);
    m_laAssign.bind(cmd);
    assign(1);
}

void GateLighting::recordIl(VkCommandBuffer cmd, vk::Image& indirect, float clampDistance) {
    if (indirect.view() != m_boundIndirect) {
        m_il.set.writeStorageImage(9, indirect.view());
        m_boundIndirect = indirect.view();
    }
    m_il.bind(cmd);
    const struct {
        float clamp;
        uint32_t capacity;
    } push{clampDistance, uint32_t(m_capacity)};
    m_il.layout.push(cmd, push);
    vk::dispatch2D(cmd, m_width, m_height, kGroup, kGroup);
    vk::memoryBarrier(cmd);
    vk::hostReadBarrier(cmd);
}

GateLightingStats GateLighting::readStats() {
    GateLightingStats s;
    uint32_t state[8] = {};
    m_state.download(state, sizeof(state));
    s.geometryClusters = state[0];
    s.entries = state[1];
    s.overflow = s.entries > m_capacity ? s.entries - m_capacity : 0;
    const uint32_t groups = groupCount(m_width, m_height);
    std::vector<glm::vec4> sums(groups);
    m_partials.download(sums.data(), VkDeviceSize(groups) * 16);
    for (const glm::vec4& g : sums) {
        s.keptIrradiance += g.x;
        s.removedIrradiance += g.y;
    }
    m_sharePartials.download(sums.data(), VkDeviceSize(groups) * 16);
    for (const glm::vec4& g : sums) {
        s.unshadowedRadiance += g.x;
        s.sameClusterRadiance += g.y;
    }
    const std::vector<GpuVpl> vpls = m_vpls.downloadVector<GpuVpl>(m_vplCount);
    const std::vector<uint32_t> clusters = m_vplClusters.downloadVector<uint32_t>(m_vplCount);
    for (uint32_t i = 0; i < m_vplCount; ++i) {
        if (vpls[i].position.w < 0.5f) continue;
        ++s.validVpls;
        if (clusters[i] == kNone) ++s.vplsWithoutCluster;
    }
    return s;
}

uint64_t GateLighting::bytes() const {
    uint64_t total = 0;
    for (const vk::Buffer* b :
         {&m_vplClusters, &m_gates, &m_clusterStart, &m_clusterGates, &m_geo, &m_counts, &m_offsets,
          &m_entries, &m_state, &m_partials, &m_sharePartials})
        total += b->size();
    return total + uint64_t(m_width) * m_height * 4;
}

}  // namespace gilab::topo
