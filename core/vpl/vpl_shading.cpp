#include "core/vpl/vpl_shading.h"

#include <vector>

#include "core/passes/gbuffer.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/vpl/paraboloid_maps.h"

namespace gilab {
namespace {

struct GatherPush {  // mirrors vpl_gather.comp
    glm::vec2 bounceScale;
    float clampDistance, biasTexels;
    uint32_t count, interleave, mapResolution, visibility, firstCount, groupSize, subsets, pad;
};
struct BlurPush {  // mirrors vpl_blur.comp
    uint32_t mode;
    int32_t radius;
};

constexpr uint32_t kGroup = 8;

uint32_t groupCount(uint32_t w, uint32_t h) {
    return ((w + kGroup - 1) / kGroup) * ((h + kGroup - 1) / kGroup);
}

}  // namespace

InterleaveSubsets interleaveSubsetsFrom(const std::string& name) {
    if (name == "fold") return InterleaveSubsets::Fold;
    if (name == "blocks") return InterleaveSubsets::Blocks;
    if (name == "modulo") return InterleaveSubsets::Modulo;
    throw Error("interleave subsets '" + name + "': expected fold, blocks or modulo");
}

VplShading::VplShading(vk::Context& ctx, GBuffer& gbuffer, const vk::Buffer& vpls,
                       const vk::Buffer& clusters, ParaboloidMaps* maps, const std::string& tag)
    : m_width(gbuffer.width), m_height(gbuffer.height), m_hasMaps(maps != nullptr) {
    auto frameImage = [&](const std::string& name) {
        return vk::Image(ctx, vk::imageDesc2D(m_width, m_height, VK_FORMAT_R32G32B32A32_SFLOAT,
                                              VK_IMAGE_USAGE_STORAGE_BIT, tag + name));
    };
    m_irradiance = frameImage("/irradiance");
    m_temp = frameImage("/irradiance_blur");
    m_partials = vk::Buffer(ctx, VkDeviceSize(groupCount(m_width, m_height)) * 16,
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryUsage::Readback,
                            tag + "/clamp_sums");
    if (!maps) {
        vk::ImageDesc d;
        d.kind = vk::ImageKind::Image2DArray;
        d.format = VK_FORMAT_R32G32B32A32_SFLOAT;
        d.usage = VK_IMAGE_USAGE_STORAGE_BIT;
        d.name = tag + "/no_maps";
        m_dummyMap = vk::Image(ctx, d);
        ctx.submitAndWait([&](VkCommandBuffer cmd) {
            m_dummyMap.clearColor(cmd, VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}});
        });
    } else {
        m_mapResolution = maps->settings().resolution;
    }
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
        m_irradiance.clearColor(cmd, VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}});
        m_temp.clearColor(cmd, VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}});
    });

    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    const VkDescriptorType img = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    const VkDescriptorType buf = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    m_gatherSetLayout = vk::DescriptorSetLayout(ctx,
                                                {{0, img, 1, cs},
                                                 {1, img, 1, cs},
                                                 {2, buf, 1, cs},
                                                 {3, buf, 1, cs},
                                                 {4, img, 1, cs},
                                                 {5, img, 1, cs},
                                                 {6, buf, 1, cs}},
                                                tag + "/gather");
    m_gatherSet = vk::DescriptorSet(ctx, m_gatherSetLayout, 0, tag + "/gather");
    m_gatherSet.writeStorageImage(0, gbuffer.position.view());
    m_gatherSet.writeStorageImage(1, gbuffer.normal.view());
    m_gatherSet.writeBuffer(2, vpls);
    m_gatherSet.writeBuffer(3, clusters);
    m_gatherSet.writeStorageImage(4, maps ? maps->position().view() : m_dummyMap.view());
    m_gatherSet.writeStorageImage(5, m_irradiance.view());
    m_gatherSet.writeBuffer(6, m_partials);
    m_gatherLayout = vk::PipelineLayout(ctx, {m_gatherSetLayout.handle()}, sizeof(GatherPush));
    m_gather = vk::ComputePipeline(ctx, "common/vpl_gather.comp", m_gatherLayout);

    std::vector<vk::DescriptorBinding> blur;
    for (uint32_t b = 0; b < 6; ++b)
        blur.push_back({b, img, 1, cs});
    m_blurSetLayout = vk::DescriptorSetLayout(ctx, blur, tag + "/blur");
    m_blurSet = vk::DescriptorSet(ctx, m_blurSetLayout, 0, tag + "/blur");
    m_blurSet.writeStorageImage(0, gbuffer.position.view());
    m_blurSet.writeStorageImage(1, gbuffer.normal.view());
    m_blurSet.writeStorageImage(2, gbuffer.albedo.view());
    m_blurSet.writeStorageImage(3, m_irradiance.view());
    m_blurSet.writeStorageImage(4, m_temp.view());
    m_blurLayout = vk::PipelineLayout(ctx, {m_blurSetLayout.handle()}, sizeof(BlurPush));
    m_blur = vk::ComputePipeline(ctx, "common/vpl_blur.comp", m_blurLayout);
}

void VplShading::bind(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
                      const vk::PipelineLayout& layout, const vk::DescriptorSet& set) {
    pipeline.bind(cmd);
    VkDescriptorSet s = set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout.handle(), 0, 1, &s, 0,
                            nullptr);
}

void VplShading::recordGather(VkCommandBuffer cmd, uint32_t count, uint32_t firstCount,
                              uint32_t groupSize) {
    if (m_settings.interleave == 0) throw Error("VplShading: interleave must be >= 1");
    bind(cmd, m_gather, m_gatherLayout, m_gatherSet);
    const GatherPush push{m_settings.bounceScale,
                          m_settings.clampDistance,
                          m_settings.visibilityBiasTexels,
                          count,
                          m_settings.interleave,
                          m_mapResolution,
                          (m_settings.visibility && m_hasMaps) ? 1u : 0u,
                          firstCount,
                          groupSize,
                          uint32_t(m_settings.subsets),
                          0u};
    m_gatherLayout.push(cmd, push);
    vk::dispatch2D(cmd, m_width, m_height, kGroup, kGroup);
    vk::memoryBarrier(cmd);
    vk::hostReadBarrier(cmd);  // the clamp sums are read on the host after the submission
}

void VplShading::recordResolve(VkCommandBuffer cmd, vk::Image& indirect) {
    if (indirect.view() != m_boundIndirect) {
        m_blurSet.writeStorageImage(5, indirect.view());
        m_boundIndirect = indirect.view();
    }
    bind(cmd, m_blur, m_blurLayout, m_blurSet);
    const int32_t radius = int32_t(m_settings.blurRadius);
    auto pass = [&](uint32_t mode) {
        const BlurPush push{mode, radius};
        m_blurLayout.push(cmd, push);
        vk::dispatch2D(cmd, m_width, m_height, kGroup, kGroup);
        vk::memoryBarrier(cmd);
    };
    if (radius > 0) {
        pass(0);
        pass(1);
    } else {
        pass(2);
    }
}

VplClampStats VplShading::readClampStats() {
    const uint32_t groups = groupCount(m_width, m_height);
    std::vector<glm::vec4> sums(groups);
    m_partials.download(sums.data(), VkDeviceSize(groups) * 16);
    VplClampStats s;
    for (const glm::vec4& g : sums) {
        s.keptIrradiance += g.x;
        s.removedIrradiance += g.y;
    }
    s.pixels = m_width * m_height;
    return s;
}

}  // namespace gilab
