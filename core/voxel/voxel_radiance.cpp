#include "core/voxel/voxel_radiance.h"

#include <string>

#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"

namespace gilab {
namespace {

constexpr const char* kFaceNames[VoxelRadiance::kFaceCount] = {"-X", "+X", "-Y", "+Y", "-Z", "+Z"};

struct FilterPush {
    uint32_t dstSize;
    uint32_t srcSize;
    uint32_t mode;  // isotropic: 0 box, 1 Gaussian
    uint32_t pad;
};

bool isPowerOfTwo(uint32_t n) {
    return n != 0 && (n & (n - 1)) == 0;
}

uint32_t log2u(uint32_t n) {
    uint32_t l = 0;
    while (n > 1) {
        n >>= 1;
        ++l;
    }
    return l;
}

vk::Image makeVolume(vk::Context& ctx, uint32_t n, VkFormat format, uint32_t mips,
                     const std::string& name, uint32_t slabs = 1) {
    vk::ImageDesc desc;
    desc.kind = vk::ImageKind::Image3D;
    desc.format = format;
    desc.width = desc.height = n;
    desc.depth = n * slabs;
    desc.mipLevels = mips;
    desc.usage =
        VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    desc.name = name;
    return vk::Image(ctx, desc);
}

}  // namespace

VoxelRadiance::VoxelRadiance(vk::Context& ctx, const VoxelGrid& grid,
                             const VoxelRadianceOptions& options, const std::string& memoryTag)
    : m_ctx(ctx), m_grid(grid), m_options(options) {
    const uint32_t n = grid.resolution();
    checkVoxelResolution(n);
    if (!isPowerOfTwo(n)) {
        throw Error("VoxelRadiance: resolution = " + std::to_string(n) +
                    " must be a power of two (the mip pyramid halves down to 1^3)");
    }
    m_format =
        options.fullPrecision ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R16G16B16A16_SFLOAT;
    const std::string tag = memoryTag.empty() ? std::string("radiance") : memoryTag;
    const uint32_t filteredLevels = log2u(n);  // (N/2)^3 ... 1^3
    m_base = makeVolume(ctx, n, m_format, 1, tag + "/base");
    m_filtered = makeVolume(ctx, n / 2, m_format, filteredLevels,
                            tag + (options.anisotropic ? "/faces" : "/isotropic"), slabCount());

    vk::SamplerDesc sd;
    sd.filter = VK_FILTER_LINEAR;
    sd.mipmap = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    sd.address = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
    sd.borderColor = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;
    sd.name = tag + "/sampler";
    m_sampler = vk::Sampler(ctx, sd);

    m_noNormals = makeVolume(ctx, 1, m_format, 1, tag + "/no_normals");
    m_normalView = m_noNormals.view();

    // Filter passes: binding 0 = source level, binding 1 = destination level (atlas mips; the
    // base is the source of the first), binding 2 = surface normals (facing weights of the first
    // directional level).
    const VkShaderStageFlags cs = VK_SHADER_STAGE_COMPUTE_BIT;
    m_setLayout = vk::DescriptorSetLayout(ctx,
                                          {{0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                           {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, cs},
                                           {2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, cs}},
                                          tag + "/filter");
    m_pipelineLayout =
        vk::PipelineLayout(ctx, {m_setLayout.handle()}, sizeof(FilterPush), cs, tag + "/filter");
    const std::string suffix = options.fullPrecision ? "_f32.comp" : ".comp";
    if (options.anisotropic) {
        const std::string shader = "common/voxel_radiance_aniso" + suffix;
        m_firstLevel = vk::ComputePipeline(ctx, shader, m_pipelineLayout, {vk::specBool(0, true)});
        m_nextLevel = vk::ComputePipeline(ctx, shader, m_pipelineLayout, {vk::specBool(0, false)});
    } else {
        m_firstLevel =
            vk::ComputePipeline(ctx, "common/voxel_radiance_iso" + suffix, m_pipelineLayout);
    }
    for (uint32_t level = 0; level < filteredLevels; ++level) {
        vk::DescriptorSet set(ctx, m_setLayout, 0, tag + "/filter.level" + std::to_string(level));
        set.writeStorageImage(0, level == 0 ? m_base.view() : m_filtered.mipView(level - 1));
        set.writeStorageImage(1, m_filtered.mipView(level));
        set.writeSampledImage(2, m_normalView, m_sampler.handle(), m_normalLayout);
        m_sets.push_back(std::move(set));
    }

    // Everything lives in GENERAL from here on, starting transparent black.
    ctx.submitAndWait([&](VkCommandBuffer cmd) {
        const VkClearColorValue zero{};
        m_base.clearColor(cmd, zero);
        m_noNormals.clearColor(cmd, zero);
        m_filtered.clearColor(cmd, zero);
    });
}

void VoxelRadiance::setSurfaceNormals(const vk::Image& normals) {
    if (normals.width() != m_grid.resolution() || normals.desc().depth != m_grid.resolution()) {
        throw Error("VoxelRadiance: surface normals are " + std::to_string(normals.width()) +
                    "^3, the grid is " + std::to_string(m_grid.resolution()) + "^3");
    }
    m_normalView = normals.view();
    m_normalLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    for (vk::DescriptorSet& set : m_sets)
        set.writeSampledImage(2, m_normalView, m_sampler.handle(), m_normalLayout);
}

void VoxelRadiance::clearBase(VkCommandBuffer cmd) {
    const VkClearColorValue zero{};
    m_base.clearColor(cmd, zero);  // transition (no-op in GENERAL) + clear + barrier
}

void VoxelRadiance::filter(VkCommandBuffer cmd) {
    vk::memoryBarrier(cmd);  // the caller's writes to base()
    const uint32_t n = m_grid.resolution();
    for (uint32_t level = 0; level < m_sets.size(); ++level) {
        const bool next = m_options.anisotropic && level > 0;
        const vk::ComputePipeline& pipeline = next ? m_nextLevel : m_firstLevel;
        pipeline.bind(cmd);
        VkDescriptorSet set = m_sets[level].handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_pipelineLayout.handle(), 0,
                                1, &set, 0, nullptr);
        FilterPush push{};
        push.srcSize = n >> level;
        push.dstSize = n >> (level + 1);
        push.mode = m_options.isotropicFilter == VoxelMipFilter::Gaussian ? 1u : 0u;
        m_pipelineLayout.push(cmd, push);
        const uint32_t groups = (push.dstSize + 3) / 4;
        vkCmdDispatch(cmd, groups, groups, groups);
        vk::memoryBarrier(cmd);  // this level is the next one's source, and the cones' input
    }
}

uint32_t VoxelRadiance::levels() const {
    return log2u(m_grid.resolution()) + 1;
}

size_t VoxelRadiance::memoryBytesFor(uint32_t n, const VoxelRadianceOptions& options) {
    const size_t texel = options.fullPrecision ? 16 : 8;
    size_t filtered = 0;
    for (size_t s = n / 2; s >= 1; s /= 2)
        filtered += s * s * s;
    const size_t volumes = options.anisotropic ? kFaceCount : 1;
    return texel * (size_t(n) * n * n + volumes * filtered);
}

size_t VoxelRadiance::memoryBytes() const {
    return memoryBytesFor(m_grid.resolution(), m_options);
}

void VoxelRadiance::addLayoutBindings(std::vector<VkDescriptorSetLayoutBinding>& out,
                                      uint32_t first, VkShaderStageFlags stages) {
    for (uint32_t i = 0; i < kBindingCount; ++i) {
        VkDescriptorSetLayoutBinding b{};
        b.binding = first + i;
        b.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        b.descriptorCount = 1;
        b.stageFlags = stages;
        out.push_back(b);
    }
}

void VoxelRadiance::addLayoutBindings(std::vector<vk::DescriptorBinding>& out, uint32_t first,
                                      VkShaderStageFlags stages) {
    for (uint32_t i = 0; i < kBindingCount; ++i)
        out.push_back({first + i, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, stages, false});
}

void VoxelRadiance::writeDescriptors(vk::DescriptorSet& set, uint32_t first) const {
    const VkImageLayout general = VK_IMAGE_LAYOUT_GENERAL;
    set.writeSampledImage(first, m_base.view(), m_sampler.handle(), general);
    set.writeSampledImage(first + 1, m_filtered.view(), m_sampler.handle(), general);
    set.writeSampledImage(first + 2, m_normalView, m_sampler.handle(), m_normalLayout);
}

std::vector<glm::vec4> VoxelRadiance::readLevel(uint32_t level, int faceIndex) {
    if (level >= levels()) {
        throw Error("VoxelRadiance::readLevel: level = " + std::to_string(level) +
                    " >= " + std::to_string(levels()));
    }
    if (level > 0 && (faceIndex < 0 || faceIndex >= int(kFaceCount))) {
        throw Error("VoxelRadiance::readLevel: face = " + std::to_string(faceIndex) +
                    " outside [0, 5]");
    }
    std::vector<float> f =
        level == 0 ? m_base.readbackFloat(m_ctx) : m_filtered.readbackFloat(m_ctx, 0, level - 1);
    // A face's slab is a contiguous z range of its level: texels [slab n^3, (slab + 1) n^3)
    const size_t n = size_t(m_grid.resolution() >> level);
    const size_t first = level == 0 ? 0 : size_t(m_options.anisotropic ? faceIndex : 0) * n * n * n;
    std::vector<glm::vec4> out(n * n * n);
    for (size_t i = 0; i < out.size(); ++i) {
        const float* t = &f[4 * (first + i)];
        out[i] = glm::vec4(t[0], t[1], t[2], t[3]);
    }
    return out;
}

}  // namespace gilab
