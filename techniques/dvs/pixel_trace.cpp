#include "pixel_trace.h"

#include <cmath>

#include <glm/glm.hpp>

#include "core/passes/gbuffer.h"
#include "core/passes/shadow_maps.h"
#include "core/passes/shared_passes.h"
#include "core/scene/camera.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/voxel/cone_set.h"
#include "core/voxel/voxel_radiance.h"
#include "dvs_gpu.h"

namespace gilab {
namespace {

/** Mirrors TraceUniforms in techniques/dvs/shaders/trace.comp (std140). */
struct TraceUniforms {
    GpuVoxelGrid grid;
    GpuConeTraceParams cone;
    GpuConeSet diffuse;
    glm::vec4 camera;    // xyz eye, w origin offset (world)
    glm::vec4 specular;  // x on, y fixed tan(theta/2) (0 = from roughness)
    glm::vec4 shadow;    // x shadow cone tan(theta/2), y AO lambda (1/world)
    glm::uvec4 size;     // x width, y height, z pass light count
    glm::uvec4 flags;    // x cone shadows, y source composition, z AO
};

constexpr uint32_t kIndirectBinding = 4;
constexpr uint32_t kDirectBinding = 5;
constexpr uint32_t kAoBinding = 6;
constexpr uint32_t kUniformBinding = 7;
constexpr uint32_t kShadowBinding = 8;
constexpr uint32_t kConeBinding = 12;

float tanHalfDeg(float fullDeg) {
    return std::tan(0.5f * glm::radians(fullDeg));
}

}  // namespace

DvsPixelTrace::DvsPixelTrace(vk::Context& ctx, SharedPasses& shared, VoxelRadiance& radiance,
                             const std::string& memoryTag)
    : m_ctx(ctx), m_shared(shared), m_radiance(radiance) {
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    vk::ImageDesc ao;
    ao.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    ao.width = shared.width();
    ao.height = shared.height();
    ao.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    ao.name = memoryTag + "/ao";
    m_ao = vk::Image(ctx, ao);
    m_uniforms = vk::Buffer(ctx, sizeof(TraceUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                            vk::MemoryUsage::Upload, memoryTag + "/uniforms");

    std::vector<vk::DescriptorBinding> bindings;
    for (uint32_t b = 0; b <= kAoBinding; ++b)
        bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs});
    bindings.push_back({kUniformBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, cs});
    for (const vk::DescriptorBinding& b : ShadowMaps::descriptorBindings(kShadowBinding, cs))
        bindings.push_back(b);
    VoxelRadiance::addLayoutBindings(bindings, kConeBinding, cs);
    m_setLayout = vk::DescriptorSetLayout(ctx, bindings, memoryTag + "/trace");
    m_set = vk::DescriptorSet(ctx, m_setLayout, 0, memoryTag + "/trace");
    GBuffer& gb = shared.gbuffer();
    m_set.writeStorageImage(0, gb.position.view());
    m_set.writeStorageImage(1, gb.normal.view());
    m_set.writeStorageImage(2, gb.albedo.view());
    m_set.writeStorageImage(3, gb.material.view());
    m_set.writeStorageImage(kAoBinding, m_ao.view());
    m_set.writeUniformBuffer(kUniformBinding, m_uniforms);
    shared.shadows().writeDescriptors(m_set, kShadowBinding);
    radiance.writeDescriptors(m_set, kConeBinding);
    m_layout = vk::PipelineLayout(ctx, {m_setLayout.handle()});
    m_pipeline = vk::ComputePipeline(ctx, "dvs/trace.comp", m_layout);
}

void DvsPixelTrace::record(VkCommandBuffer cmd, const DvsSettings& s, const Camera& camera,
                           vk::Image& indirect, vk::Image& direct) {
    if (indirect.view() != m_boundIndirect || direct.view() != m_boundDirect) {
        m_set.writeStorageImage(kIndirectBinding, indirect.view());
        m_set.writeStorageImage(kDirectBinding, direct.view());
        m_boundIndirect = indirect.view();
        m_boundDirect = direct.view();
    }
    const VoxelGrid& grid = m_radiance.grid();
    const float v0 = grid.voxelSize();
    const float offset = s.originOffset * v0;
    const ConeSet diffuse = makeDiffuseConeSet(s.diffuseCones, s.diffuseApertureDeg);
    const bool source = s.combine == DvsCombine::Source;

    TraceUniforms u{};
    u.grid = grid.gpu();
    // t0: the same offset again along the cone (repo: x + n s + d t, t from s), at least v0.
    u.cone =
        makeConeTraceParams(grid, s.stepFactor, s.maxDistance * grid.side(), std::max(offset, v0),
                            s.opacityCutoff, 0.0f, s.lodOffset, s.lift, s.liftBlend);
    u.diffuse = toGpu(diffuse);
    u.camera = glm::vec4(camera.position, offset);
    u.specular = glm::vec4(s.specular ? 1.0f : 0.0f,
                           s.specularApertureDeg > 0.0f ? tanHalfDeg(s.specularApertureDeg) : 0.0f,
                           0.0f, 0.0f);
    // E11: lambda r / G with r = cone radius = t tan(theta/2); voxel_cone.glsl uses lambda' t.
    const float aoLambda = s.aoFalloff * tanHalfDeg(s.diffuseApertureDeg) / grid.side();
    u.shadow = glm::vec4(tanHalfDeg(s.shadowConeApertureDeg), aoLambda, 0.0f, 0.0f);
    u.size = glm::uvec4(m_shared.width(), m_shared.height(), m_shared.shadows().lightCount(), 0u);
    u.flags = glm::uvec4(s.pixelShadows == DvsPixelShadows::Cone ? 1u : 0u, source ? 1u : 0u,
                         (s.aoView || source) ? 1u : 0u, 0u);
    m_uniforms.upload(&u, sizeof(u));

    m_ao.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    m_pipeline.bind(cmd);
    VkDescriptorSet set = m_set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set, 0,
                            nullptr);
    vk::dispatch2D(cmd, m_shared.width(), m_shared.height());
    vk::memoryBarrier(cmd);
}

}  // namespace gilab
