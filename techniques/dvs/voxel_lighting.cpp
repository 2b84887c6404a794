#include "voxel_lighting.h"

#include <algorithm>

#include <glm/glm.hpp>

#include "core/passes/shadow_maps.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/voxel/cone_set.h"
#include "core/voxel/voxel_radiance.h"
#include "core/voxel/voxelizer.h"
#include "dvs_gpu.h"

namespace gilab {
namespace {

/** Mirrors VoxelDirectPush in techniques/dvs/shaders/voxel_direct.comp. */
struct VoxelDirectPush {
    GpuVoxelGrid grid;
    glm::vec4 params;  // x kappa, y min emitter-sample distance (world)
    glm::uvec4 modes;  // x lambert, y shadows, z light count, w shadow maps on
};

/** Mirrors BounceUniforms in techniques/dvs/shaders/voxel_bounce.comp (std140). */
struct BounceUniforms {
    GpuVoxelGrid grid;
    GpuConeTraceParams cone;
    glm::vec4 misc;  // x origin offset along the normal (world)
    GpuConeSet cones;
};

constexpr uint32_t kShadowBinding = 3;      // voxel_direct.comp
constexpr uint32_t kBounceConeBinding = 4;  // voxel_bounce.comp
constexpr uint32_t kGroup = 4;

uint32_t groupsFor(uint32_t n) {
    return (n + kGroup - 1) / kGroup;
}

}  // namespace

DvsVoxelLighting::DvsVoxelLighting(vk::Context& ctx, Voxelizer& voxelizer, VoxelRadiance& radiance,
                                   ShadowMaps& shadows, const DvsSettings& settings,
                                   const std::string& memoryTag)
    : m_ctx(ctx),
      m_voxelizer(voxelizer),
      m_radiance(radiance),
      m_shadows(shadows),
      m_settings(settings) {
    if (radiance.format() != VK_FORMAT_R16G16B16A16_SFLOAT)
        throw Error("DvsVoxelLighting: the shaders declare rgba16f radiance volumes");
    if (radiance.grid().resolution() != voxelizer.grid().resolution())
        throw Error("DvsVoxelLighting: radiance and voxelizer grids differ");
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    vk::SamplerDesc nearest;
    nearest.filter = VK_FILTER_NEAREST;
    nearest.mipmap = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    nearest.name = memoryTag + "/nearest";
    m_nearest = vk::Sampler(ctx, nearest);
    VoxelVolumes& volumes = voxelizer.volumes();

    // L1: voxel volumes, base, shadow.glsl.
    std::vector<vk::DescriptorBinding> direct = {
        {0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
        {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
        {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs}};
    for (const vk::DescriptorBinding& b : ShadowMaps::descriptorBindings(kShadowBinding, cs))
        direct.push_back(b);
    m_directSetLayout = vk::DescriptorSetLayout(ctx, direct, memoryTag + "/voxel_direct");
    m_directSet = vk::DescriptorSet(ctx, m_directSetLayout, 0, memoryTag + "/voxel_direct");
    m_directSet.writeSampledImage(0, volumes.albedoOpacity.view(), m_nearest.handle());
    m_directSet.writeSampledImage(1, volumes.normal.view(), m_nearest.handle());
    m_directSet.writeStorageImage(2, radiance.base().view());
    shadows.writeDescriptors(m_directSet, kShadowBinding);
    m_directLayout = vk::PipelineLayout(ctx, {m_directSetLayout.handle()}, sizeof(VoxelDirectPush));
    m_direct = vk::ComputePipeline(ctx, "dvs/voxel_direct.comp", m_directLayout);

    if (settings.bounces < 2) return;
    // G1: voxel volumes, scratch output, uniforms, the radiance pyramid.
    const uint32_t n = radiance.grid().resolution();
    vk::ImageDesc scratch;
    scratch.kind = vk::ImageKind::Image3D;
    scratch.format = radiance.format();
    scratch.width = scratch.height = scratch.depth = n;
    scratch.usage = VK_IMAGE_USAGE_STORAGE_BIT;
    scratch.name = memoryTag + "/bounce_scratch";
    m_scratch = vk::Image(ctx, scratch);

    const VoxelGrid& grid = radiance.grid();
    const float v0 = grid.voxelSize();
    const ConeSet cones = makeDiffuseConeSet(kDvsBounceConeCount, dvsBounceApertureDeg());
    BounceUniforms u{};
    u.grid = grid.gpu();
    // G1 marches like the pixel cones (issue 9): the same step, distance, level mapping, lift
    // and cutoff (the repo's G1 fixed step 0.5, max 0.95 G and E7 literally); its own cone set.
    const DvsSettings& s = settings;
    u.cone = makeConeTraceParams(grid, s.stepFactor, s.maxDistance * grid.side(),
                                 std::max(s.originOffset * v0, v0), s.opacityCutoff, 0.0f,
                                 s.lodOffset, s.lift, s.liftBlend);
    u.misc = glm::vec4(s.originOffset * v0, 0.0f, 0.0f, 0.0f);
    u.cones = toGpu(cones);
    m_bounceUniforms = vk::Buffer(ctx, sizeof(BounceUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                                  vk::MemoryUsage::Upload, memoryTag + "/bounce_uniforms");
    m_bounceUniforms.upload(&u, sizeof(u));

    std::vector<vk::DescriptorBinding> bounce = {
        {0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
        {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs},
        {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
        {3, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, cs}};
    VoxelRadiance::addLayoutBindings(bounce, kBounceConeBinding, cs);
    m_bounceSetLayout = vk::DescriptorSetLayout(ctx, bounce, memoryTag + "/voxel_bounce");
    m_bounceSet = vk::DescriptorSet(ctx, m_bounceSetLayout, 0, memoryTag + "/voxel_bounce");
    m_bounceSet.writeSampledImage(0, volumes.albedoOpacity.view(), m_nearest.handle());
    m_bounceSet.writeSampledImage(1, volumes.normal.view(), m_nearest.handle());
    m_bounceSet.writeStorageImage(2, m_scratch.view());
    m_bounceSet.writeUniformBuffer(3, m_bounceUniforms);
    radiance.writeDescriptors(m_bounceSet, kBounceConeBinding);
    m_bounceLayout = vk::PipelineLayout(ctx, {m_bounceSetLayout.handle()});
    m_bounce = vk::ComputePipeline(ctx, "dvs/voxel_bounce.comp", m_bounceLayout);
}

void DvsVoxelLighting::recordDirect(VkCommandBuffer cmd) {
    const VoxelGrid& grid = m_radiance.grid();
    m_radiance.base().transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    m_direct.bind(cmd);
    VkDescriptorSet set = m_directSet.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_directLayout.handle(), 0, 1,
                            &set, 0, nullptr);
    VoxelDirectPush push{};
    push.grid = grid.gpu();
    push.params = glm::vec4(m_settings.softShadowKappa,
                            kDvsEmitterMinDistanceVoxels * grid.voxelSize(), 0.0f, 0.0f);
    push.modes = glm::uvec4(uint32_t(m_settings.lambert), uint32_t(m_settings.voxelShadows),
                            m_shadows.lightCount(), m_shadows.settings().enabled ? 1u : 0u);
    m_directLayout.push(cmd, push);
    const uint32_t g = groupsFor(grid.resolution());
    vkCmdDispatch(cmd, g, g, g);
    vk::memoryBarrier(cmd);
}

void DvsVoxelLighting::recordBounce(VkCommandBuffer cmd) {
    if (!m_scratch.valid())
        throw Error("DvsVoxelLighting: bounces = 1 (or the scratch volume was released)");
    const uint32_t n = m_radiance.grid().resolution();
    m_scratch.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    m_bounce.bind(cmd);
    VkDescriptorSet set = m_bounceSet.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_bounceLayout.handle(), 0, 1,
                            &set, 0, nullptr);
    const uint32_t g = groupsFor(n);
    vkCmdDispatch(cmd, g, g, g);
    // Copy the result over the base; the base goes back to GENERAL (VoxelRadiance contract).
    vk::Image& base = m_radiance.base();
    m_scratch.transition(cmd, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    base.transition(cmd, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    VkImageCopy region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.extent = {n, n, n};
    vkCmdCopyImage(cmd, m_scratch.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, base.handle(),
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    base.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    vk::memoryBarrier(cmd);
}

}  // namespace gilab
