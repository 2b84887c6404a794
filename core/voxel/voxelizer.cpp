#include "core/voxel/voxelizer.h"

#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include "core/gpu/gpu_scene.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "core/vk/rendering.h"
#include "core/vk/timer.h"

namespace gilab {
namespace {

constexpr const char* kPlaneNames[Voxelizer::kAccumulatorWords] = {
    "albedo.r", "albedo.g",   "albedo.b",   "normal.x",   "normal.y",
    "normal.z", "emission.r", "emission.g", "emission.b", "count"};

vk::Image makeVolume(vk::Context& ctx, uint32_t n, VkFormat format, const char* name) {
    vk::ImageDesc desc;
    desc.kind = vk::ImageKind::Image3D;
    desc.format = format;
    desc.width = desc.height = desc.depth = n;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    desc.name = std::string("voxel/") + name;
    return vk::Image(ctx, desc);
}

}  // namespace

size_t VoxelData::occupiedCount() const {
    size_t n = 0;
    for (const glm::vec4& a : albedoOpacity)
        n += a.w > 0.0f ? 1 : 0;
    return n;
}

Voxelizer::Voxelizer(vk::Context& ctx, const vk::GpuScene& scene, const VoxelGrid& grid,
                     const VoxelizerOptions& options)
    : m_ctx(ctx), m_scene(scene), m_grid(grid) {
    checkVoxelResolution(grid.resolution());
    m_floatAtomics = ctx.hasFloatAtomics() && !options.forceFixedPoint;
    m_format =
        options.fullPrecision ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R16G16B16A16_SFLOAT;
    std::vector<VkDescriptorSetLayout> voxelizeSets = {scene.layout().handle()};
    vk::GraphicsPipelineDesc desc;
    if (options.fragmentCapacity > 0) {
        // Fragment-list mode: the lists at set 1, no accumulators, volumes or resolve.
        m_fragments = std::make_unique<VoxelFragmentLists>(ctx, grid, options.fragmentCapacity);
        voxelizeSets.push_back(m_fragments->layout().handle());
        desc.fragmentShader = "common/voxelize_fragments.frag";
    } else {
        createAccumulation(options);
        voxelizeSets.push_back(m_accumLayout.handle());
        desc.fragmentShader =
            m_floatAtomics ? "common/voxelize.frag" : "common/voxel_voxelize_fixed.frag";
    }
    m_voxelizeLayout = vk::PipelineLayout(ctx, voxelizeSets, sizeof(GpuVoxelGrid));
    desc.vertexShader = "common/voxelize.vert";
    desc.geometryShader = "common/voxelize.geom";
    desc.sceneVertexInput = false;  // pulled from the scene set
    desc.depthTest = false;
    desc.depthWrite = false;
    desc.cull = VK_CULL_MODE_NONE;
    desc.name = "voxel/voxelize";
    m_voxelize = vk::GraphicsPipeline(m_ctx, desc, m_voxelizeLayout);
}

void Voxelizer::createAccumulation(const VoxelizerOptions& options) {
    vk::Context& ctx = m_ctx;
    // One buffer per accumulator word keeps each binding under maxStorageBufferRange.
    const VkDeviceSize planeBytes = VkDeviceSize(m_grid.voxelCount()) * 4;
    const VkDeviceSize maxRange = ctx.properties().limits.maxStorageBufferRange;
    if (planeBytes > maxRange) {
        // Named after the techniques' parameter, with the largest grid this device allows
        uint32_t largest = uint32_t(std::cbrt(double(maxRange / 4)));
        while (VkDeviceSize(largest + 1) * (largest + 1) * (largest + 1) * 4 <= maxRange)
            ++largest;
        while (largest > 0 && VkDeviceSize(largest) * largest * largest * 4 > maxRange)
            --largest;
        throw DeviceLimitError("voxel_resolution = " + std::to_string(m_grid.resolution()) +
                               " is too large for this device: one voxelizer accumulator needs " +
                               std::to_string(planeBytes >> 20) +
                               " MiB, above maxStorageBufferRange (" +
                               std::to_string(maxRange >> 20) + " MiB); the largest grid here is " +
                               std::to_string(largest) + "^3");
    }
    for (uint32_t k = 0; k < kAccumulatorWords; ++k) {
        m_accumulators.emplace_back(
            ctx, planeBytes,
            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
            vk::MemoryUsage::DeviceLocal, std::string("voxel/accumulators.") + kPlaneNames[k]);
    }
    const uint32_t n = m_grid.resolution();
    m_volumes.albedoOpacity = makeVolume(ctx, n, m_format, "albedoOpacity");
    m_volumes.normal = makeVolume(ctx, n, m_format, "normal");
    m_volumes.emission = makeVolume(ctx, n, m_format, "emission");

    // Voxelization: scene set 0 + accumulators at set 1.
    m_accumLayout = vk::DescriptorSetLayout(
        ctx,
        {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kAccumulatorWords, VK_SHADER_STAGE_FRAGMENT_BIT}},
        "voxel/accumulate");
    m_accumSet = vk::DescriptorSet(ctx, m_accumLayout, 0, "voxel/accumulate");
    for (uint32_t k = 0; k < kAccumulatorWords; ++k)
        m_accumSet.writeBuffer(0, m_accumulators[k], k);

    // Resolve.
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_resolveSetLayout =
        vk::DescriptorSetLayout(ctx,
                                {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kAccumulatorWords, cs},
                                 {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                 {2, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                 {3, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs}},
                                "voxel/resolve");
    m_resolveSet = vk::DescriptorSet(ctx, m_resolveSetLayout, 0, "voxel/resolve");
    for (uint32_t k = 0; k < kAccumulatorWords; ++k)
        m_resolveSet.writeBuffer(0, m_accumulators[k], k);
    m_resolveSet.writeStorageImage(1, m_volumes.albedoOpacity.view());
    m_resolveSet.writeStorageImage(2, m_volumes.normal.view());
    m_resolveSet.writeStorageImage(3, m_volumes.emission.view());
    m_resolveLayout = vk::PipelineLayout(ctx, {m_resolveSetLayout.handle()}, sizeof(GpuVoxelGrid));
    m_resolve = vk::ComputePipeline(
        ctx, options.fullPrecision ? "common/voxel_resolve_f32.comp" : "common/voxel_resolve.comp",
        m_resolveLayout);
}

void Voxelizer::record(VkCommandBuffer cmd, vk::GpuTimer* timer) {
    if (!m_fragments && m_accumulators.empty())
        throw Error("Voxelizer: accumulators were released");
    const uint32_t n = m_grid.resolution();
    const GpuVoxelGrid push = m_grid.gpu(m_floatAtomics ? 0u : 1u);
    {
        std::optional<vk::ScopedGpuPass> pass;
        if (timer) pass.emplace(*timer, cmd, "voxelize");
        for (const vk::Buffer& plane : m_accumulators)
            vkCmdFillBuffer(cmd, plane.handle(), 0, VK_WHOLE_SIZE, 0);
        if (m_fragments) m_fragments->recordClear(cmd);
        vk::memoryBarrier(cmd);
        if (m_scene.triangleCount() > 0) {
            vk::RenderingScope scope(cmd, {n, n}, {});
            m_voxelize.bind(cmd);
            VkDescriptorSet sets[2] = {m_scene.set().handle(), m_fragments
                                                                   ? m_fragments->set().handle()
                                                                   : m_accumSet.handle()};
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, m_voxelizeLayout.handle(),
                                    0, 2, sets, 0, nullptr);
            m_voxelizeLayout.push(cmd, push);
            vkCmdDraw(cmd, 3 * m_scene.triangleCount(), 1, 0, 0);
        }
        vk::memoryBarrier(cmd);
    }
    if (m_fragments) return;  // fragment-list mode: nothing to resolve
    {
        std::optional<vk::ScopedGpuPass> pass;
        if (timer) pass.emplace(*timer, cmd, "voxel_resolve");
        for (vk::Image* v : {&m_volumes.albedoOpacity, &m_volumes.normal, &m_volumes.emission})
            v->transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
        m_resolve.bind(cmd);
        VkDescriptorSet set = m_resolveSet.handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_resolveLayout.handle(), 0, 1,
                                &set, 0, nullptr);
        m_resolveLayout.push(cmd, push);
        const uint32_t groups = (n + 3) / 4;
        vkCmdDispatch(cmd, groups, groups, groups);
        for (vk::Image* v : {&m_volumes.albedoOpacity, &m_volumes.normal, &m_volumes.emission})
            v->transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    }
}

void Voxelizer::run(vk::GpuTimer* timer) {
    m_ctx.submitAndWait([&](VkCommandBuffer cmd) {
        if (timer) timer->reset(cmd);
        record(cmd, timer);
    });
    if (growFragmentsIfOverflowed())
        m_ctx.submitAndWait([&](VkCommandBuffer cmd) { record(cmd, nullptr); });
}

bool Voxelizer::growFragmentsIfOverflowed() {
    if (!m_fragments || !m_fragments->overflowed()) return false;
    m_fragments->grow(m_fragments->written());
    return true;
}

VoxelData Voxelizer::readVoxels() {
    if (m_fragments)
        throw Error("Voxelizer: readVoxels() in fragment-list mode (no volumes); read the lists");
    VoxelData out;
    out.resolution = m_grid.resolution();
    const size_t count = m_grid.voxelCount();
    auto toVec4 = [&](vk::Image& image) {
        std::vector<float> f = image.readbackFloat(m_ctx);
        std::vector<glm::vec4> v(count);
        for (size_t i = 0; i < count; ++i)
            v[i] = glm::vec4(f[4 * i], f[4 * i + 1], f[4 * i + 2], f[4 * i + 3]);
        return v;
    };
    out.albedoOpacity = toVec4(m_volumes.albedoOpacity);
    out.normal = toVec4(m_volumes.normal);
    out.emission = toVec4(m_volumes.emission);
    out.count.assign(count, 0);
    if (!m_accumulators.empty()) {
        std::vector<uint32_t> words = m_accumulators.back().downloadVector<uint32_t>(count);
        for (size_t i = 0; i < count; ++i) {
            const uint32_t w = words[i];
            float f;
            std::memcpy(&f, &w, 4);
            out.count[i] = m_floatAtomics ? uint32_t(f + 0.5f) : w;
        }
    }
    return out;
}

}  // namespace gilab
