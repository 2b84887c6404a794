#include "svo.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "core/passes/shadow_maps.h"
#include "core/passes/shared_passes.h"
#include "core/scene/scene.h"
#include "core/util/error.h"
#include "core/vk/barrier.h"
#include "core/vk/context.h"
#include "light_injection.h"

namespace gilab::vct {
namespace {

constexpr uint32_t kNone = 0xFFFFFFFFu;
constexpr uint32_t kCounterWords = 4 + 2 * 16;  // nodes, bricks, overflow, radiance, ranges
constexpr VkShaderStageFlags kCs = VK_SHADER_STAGE_COMPUTE_BIT;

struct Push {
    glm::uvec4 args{0};  // x depth, y axis, z pass, w target (splat: x light, z mode)
    glm::vec4 scale{0};  // x units per W/m^2, y W/m^2 per unit, z 1 / pi, w irradiance cap
};
constexpr uint32_t kSplatCount = 0, kSplatIrradiance = 1;  // SVO_SPLAT_* (svo_splat_body.glsl)

// Targets of the transfer / filter passes (SVO_TARGET_* in svo_common.glsl).
enum Target : uint32_t { kAccum = 0, kRadiance = 1, kGeometry = 2, kDirectional = 3 };

bool isPowerOfTwo(uint32_t n) {
    return n != 0 && (n & (n - 1)) == 0;
}
uint32_t log2u(uint32_t n) {
    uint32_t l = 0;
    while ((1u << l) < n)
        ++l;
    return l;
}

/** Pool texture of `bricks` 3^3 bricks: bricks along x, y, z (x = y = ceil(cbrt)). */
glm::uvec3 poolBricks(uint32_t bricks, uint32_t maxDim) {
    bricks = std::max(bricks, 1u);
    const uint32_t bx =
        std::clamp<uint32_t>(uint32_t(std::ceil(std::cbrt(double(bricks)))), 1u, maxDim);
    const uint32_t by = std::min(bx, (bricks + bx - 1) / bx);
    const uint32_t bz = (bricks + bx * by - 1) / (bx * by);
    if (bz > maxDim)
        throw Error("resolution: the octree's brick pool exceeds the device's 3D image size");
    return {bx, by, bz};
}

/**
 * Conservative CPU occupancy of the leaf cells (techniques/vct/svo.md "pool sizing"): every
 * voxel whose box, grown by a quarter voxel, meets a triangle's bounding box and plane marks the
 * leaf cells whose bricks hold that voxel centre (cells v/2, and v/2 - 1 for even v). It contains
 * the voxelizer's coverage (exact triangle/box overlap), so the GPU build never needs more.
 */
std::vector<uint8_t> cpuLeafOccupancy(const Scene& scene, const VoxelGrid& grid) {
    const int n = int(grid.resolution());
    const int cells = n / 2;
    std::vector<uint8_t> occ(size_t(cells) * cells * cells, 0);
    const float eps = 0.25f;
    for (size_t t = 0; t + 2 < scene.indices.size(); t += 3) {
        const glm::vec3 p0 = grid.worldToGrid(scene.vertices[scene.indices[t]].position);
        const glm::vec3 p1 = grid.worldToGrid(scene.vertices[scene.indices[t + 1]].position);
        const glm::vec3 p2 = grid.worldToGrid(scene.vertices[scene.indices[t + 2]].position);
        const glm::vec3 lo = glm::min(p0, glm::min(p1, p2)) - eps;
        const glm::vec3 hi = glm::max(p0, glm::max(p1, p2)) + eps;
        const glm::ivec3 a =
            glm::clamp(glm::ivec3(glm::floor(lo)), glm::ivec3(0), glm::ivec3(n - 1));
        const glm::ivec3 b =
            glm::clamp(glm::ivec3(glm::floor(hi)), glm::ivec3(0), glm::ivec3(n - 1));
        if (glm::any(glm::lessThan(hi, glm::vec3(0.0f))) ||
            glm::any(glm::greaterThan(lo, glm::vec3(float(n)))))
            continue;
        const glm::vec3 nrm = glm::cross(p1 - p0, p2 - p0);
        const float reach = (0.5f + eps) * (std::abs(nrm.x) + std::abs(nrm.y) + std::abs(nrm.z));
        for (int z = a.z; z <= b.z; ++z)
            for (int y = a.y; y <= b.y; ++y)
                for (int x = a.x; x <= b.x; ++x) {
                    const glm::vec3 c = glm::vec3(x, y, z) + 0.5f;
                    if (std::abs(glm::dot(nrm, c - p0)) > reach) continue;
                    const glm::ivec3 v(x, y, z);
                    for (int k = 0; k < 8; ++k) {
                        glm::ivec3 cell = v / 2;
                        bool ok = true;
                        for (int ax = 0; ax < 3; ++ax) {
                            if ((k >> ax) & 1) {
                                if (v[ax] % 2 != 0 || v[ax] == 0) ok = false;
                                cell[ax] -= 1;
                            }
                        }
                        if (!ok || glm::any(glm::greaterThanEqual(cell, glm::ivec3(cells))))
                            continue;
                        occ[size_t(cell.x) + cells * (size_t(cell.y) + size_t(cells) * cell.z)] = 1;
                    }
                }
    }
    return occ;
}

}  // namespace

SparseVoxelOctree::SparseVoxelOctree(TechniqueContext& ctx, const VoxelGrid& grid, bool anisotropic,
                                     DirectionalFilter filter, bool floatAtomics)
    : m_vk(&ctx.vk), m_grid(grid), m_anisotropic(anisotropic), m_filterMode(filter) {
    const uint32_t n = grid.resolution();
    if (!isPowerOfTwo(n))
        throw Error("resolution: the sparse voxel octree needs a power of two, got " +
                    std::to_string(n));
    m_leafDepth = log2u(n / 2);
    m_floatAtomics = floatAtomics && ctx.vk.hasFloatAtomics();
    const uint32_t depthCount = m_leafDepth + 1;

    updateLights(ctx);

    // Pool sizing from the CPU occupancy pyramid (same rule as svo_occupancy_up.comp).
    std::vector<std::vector<uint8_t>> occ(depthCount);
    occ[m_leafDepth] = cpuLeafOccupancy(ctx.scene, grid);
    for (int d = int(m_leafDepth) - 1; d >= 0; --d) {
        const int cn = 1 << d, fn = 1 << (d + 1);
        occ[d].assign(size_t(cn) * cn * cn, 0);
        for (int z = 0; z < cn; ++z)
            for (int y = 0; y < cn; ++y)
                for (int x = 0; x < cn; ++x) {
                    bool any = false;
                    for (int k = 0; k < 64 && !any; ++k) {
                        const glm::ivec3 c =
                            2 * glm::ivec3(x, y, z) - 1 + glm::ivec3(k % 4, (k / 4) % 4, k / 16);
                        if (glm::any(glm::lessThan(c, glm::ivec3(0))) ||
                            glm::any(glm::greaterThanEqual(c, glm::ivec3(fn))))
                            continue;
                        any = occ[d + 1][size_t(c.x) + fn * (size_t(c.y) + size_t(fn) * c.z)] != 0;
                    }
                    occ[d][size_t(x) + cn * (size_t(y) + size_t(cn) * z)] = any ? 1 : 0;
                }
    }
    std::vector<uint32_t> nodeBound(depthCount, 0);
    nodeBound[0] = 1;
    uint64_t bricks = 0, leafBricks = 0;
    uint32_t occWords = 0;
    m_info.originVoxelSize = glm::vec4(grid.origin(), grid.voxelSize());
    for (uint32_t d = 0; d < depthCount; ++d) {
        const uint32_t cn = 1u << d;
        const size_t cellCount = size_t(cn) * cn * cn;
        for (size_t i = 0; i < cellCount; ++i)
            bricks += occ[d][i];
        if (d == m_leafDepth)
            for (size_t i = 0; i < cellCount; ++i)
                leafBricks += occ[d][i];
        if (d + 1 < depthCount) {
            uint32_t tiles = 0;
            const uint32_t fn = 2 * cn;
            for (uint32_t z = 0; z < cn; ++z)
                for (uint32_t y = 0; y < cn; ++y)
                    for (uint32_t x = 0; x < cn; ++x) {
                        if (!occ[d][x + cn * (y + size_t(cn) * z)]) continue;
                        bool any = false;
                        for (uint32_t k = 0; k < 8; ++k) {
                            const glm::uvec3 c = 2u * glm::uvec3(x, y, z) +
                                                 glm::uvec3(k & 1u, (k >> 1) & 1u, k >> 2);
                            any = any || occ[d + 1][c.x + fn * (c.y + size_t(fn) * c.z)] != 0;
                        }
                        tiles += any ? 1 : 0;
                    }
            nodeBound[d + 1] = 8 * tiles;
        }
        m_info.depthInfo[d] = glm::uvec4(occWords, cn, nodeBound[d], 0);
        occWords += uint32_t((cellCount + 31) / 32);
    }
    m_nodeCapacity = 0;
    for (uint32_t b : nodeBound)
        m_nodeCapacity += b;
    m_brickCapacity = uint32_t(std::max<uint64_t>(bricks, 1));
    // Radiance pool: one brick per leaf; one (isotropic) or six (directional) per inner node.
    const uint64_t radiance =
        m_anisotropic ? leafBricks + uint64_t(kFaces) * (bricks - leafBricks) : bricks;
    if (radiance >= uint64_t(kNone))
        throw Error("resolution: the octree's radiance pool exceeds 2^32 bricks");
    m_radianceCapacity = uint32_t(std::max<uint64_t>(radiance, 1));

    // Brick pool textures: bx x by x bz bricks of 3^3 texels.
    const uint32_t maxDim = ctx.vk.properties().limits.maxImageDimension3D / 3;
    const glm::uvec3 gb = poolBricks(m_brickCapacity, maxDim);
    const glm::uvec3 rb = poolBricks(m_radianceCapacity, maxDim);
    m_info.dims = glm::uvec4(n, m_leafDepth, gb.x, depthCount);
    m_info.capacity = glm::uvec4(m_nodeCapacity, m_brickCapacity, m_floatAtomics ? 1u : 0u, gb.y);
    m_info.radiance =
        glm::uvec4(m_radianceCapacity, rb.x, rb.y, m_anisotropic ? uint32_t(m_filterMode) : 0u);
    const uint32_t* maxGroups = ctx.vk.properties().limits.maxComputeWorkGroupCount;
    m_maxGroups = glm::uvec2(maxGroups[0], maxGroups[1]);

    vk::Context& vk = ctx.vk;
    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    m_infoBuffer = vk::Buffer(vk, sizeof(GpuSvoInfo), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                              vk::MemoryUsage::Upload, ctx.tag("svo/info"));
    m_infoBuffer.upload(&m_info, sizeof(m_info));
    m_nodes = vk::Buffer(vk, VkDeviceSize(m_nodeCapacity) * kNodeBytes, storage,
                         vk::MemoryUsage::DeviceLocal, ctx.tag("svo/nodes"));
    m_counters = vk::Buffer(vk, kCounterWords * 4, storage, vk::MemoryUsage::DeviceLocal,
                            ctx.tag("svo/counters"));
    m_accum = vk::Buffer(vk, VkDeviceSize(m_brickCapacity) * kBrickSamples * 3 * 4, storage,
                         vk::MemoryUsage::DeviceLocal, ctx.tag("svo/irradiance_accumulators"));
    m_count = vk::Buffer(vk, VkDeviceSize(m_brickCapacity) * kBrickSamples * 4, storage,
                         vk::MemoryUsage::DeviceLocal, ctx.tag("svo/photon_counts"));
    m_lights = vk::Buffer(vk, VkDeviceSize(m_lightCount) * kLightWords * 4,
                          storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                          vk::MemoryUsage::DeviceLocal, ctx.tag("svo/light_ranges"));
    m_occupancy = vk::Buffer(vk, VkDeviceSize(std::max(occWords, 1u)) * 4, storage,
                             vk::MemoryUsage::DeviceLocal, ctx.tag("svo/occupancy"));
    vk::ImageDesc desc;
    desc.kind = vk::ImageKind::Image3D;
    desc.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    desc.width = 3 * rb.x;
    desc.height = 3 * rb.y;
    desc.depth = 3 * rb.z;
    desc.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    desc.name = ctx.tag("svo/radiance_bricks");
    m_radiance = vk::Image(vk, desc);
    desc.width = 3 * gb.x;
    desc.height = 3 * gb.y;
    desc.depth = 3 * gb.z;
    desc.name = ctx.tag("svo/geometry_bricks");
    m_geometry = vk::Image(vk, desc);
    desc.format = VK_FORMAT_R8G8B8A8_SNORM;
    desc.name = ctx.tag("svo/normal_bricks");
    m_normals = vk::Image(vk, desc);
    vk::SamplerDesc sd;
    sd.filter = VK_FILTER_LINEAR;
    sd.mipmap = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sd.maxLod = 0.0f;
    sd.name = "vct/svo_bricks";
    m_sampler = vk::Sampler(vk, sd);
    createPipelines();
}

void SparseVoxelOctree::createPipelines() {
    vk::Context& vk = *m_vk;
    m_setLayout = vk::DescriptorSetLayout(vk,
                                          {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, kCs},
                                           {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCs},
                                           {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCs},
                                           {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCs},
                                           {4, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCs},
                                           {5, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, kCs},
                                           {6, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, kCs},
                                           {7, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCs},
                                           {8, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCs},
                                           {9, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, kCs}},
                                          "vct/svo");
    m_voxelLayout =
        vk::DescriptorSetLayout(vk,
                                {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, kCs},
                                 {1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, kCs}},
                                "vct/svo_voxels");
    m_photonLayout = vk::DescriptorSetLayout(vk, {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kCs}},
                                             "vct/svo_photons");
    m_set = vk::DescriptorSet(vk, m_setLayout, 0, "vct/svo");
    m_set.writeUniformBuffer(0, m_infoBuffer);
    m_set.writeBuffer(1, m_nodes);
    m_set.writeBuffer(2, m_counters);
    m_set.writeBuffer(3, m_occupancy);
    m_set.writeBuffer(4, m_accum);
    m_set.writeStorageImage(5, m_radiance.view());
    m_set.writeStorageImage(6, m_geometry.view());
    m_set.writeBuffer(7, m_lights);
    m_set.writeBuffer(8, m_count);
    m_set.writeStorageImage(9, m_normals.view());
    m_voxelSet = vk::DescriptorSet(vk, m_voxelLayout, 0, "vct/svo_voxels");
    m_photonSet = vk::DescriptorSet(vk, m_photonLayout, 0, "vct/svo_photons");
    m_layout = vk::PipelineLayout(
        vk, {m_setLayout.handle(), m_voxelLayout.handle(), m_photonLayout.handle()}, sizeof(Push),
        kCs, "vct/svo");
    auto make = [&](const char* name) { return vk::ComputePipeline(vk, name, m_layout); };
    m_occupancyLeaf = make("vct/svo_occupancy_leaf.comp");
    m_occupancyUp = make("vct/svo_occupancy_up.comp");
    m_buildLevel = make("vct/svo_build_level.comp");
    m_neighbours = make("vct/svo_neighbours.comp");
    m_leafGeometry = make("vct/svo_leaf_geometry.comp");
    m_filter = make("vct/svo_filter.comp");
    m_filterAniso = make("vct/svo_filter_aniso.comp");
    m_splat = make(m_floatAtomics ? "vct/svo_splat_float.comp" : "vct/svo_splat.comp");
    m_transfer = make(m_floatAtomics ? "vct/svo_transfer_float.comp" : "vct/svo_transfer.comp");
    m_shade = make(m_floatAtomics ? "vct/svo_shade_float.comp" : "vct/svo_shade.comp");
    m_lightRanges = make("vct/svo_light_ranges.comp");
}

void SparseVoxelOctree::bind(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
                             bool voxelSet, bool photonSet) const {
    pipeline.bind(cmd);
    VkDescriptorSet set0 = m_set.handle();
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 0, 1, &set0, 0,
                            nullptr);
    if (voxelSet) {
        VkDescriptorSet s = m_voxelSet.handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 1, 1, &s, 0,
                                nullptr);
    }
    if (photonSet) {
        VkDescriptorSet s = m_photonSet.handle();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, m_layout.handle(), 2, 1, &s, 0,
                                nullptr);
    }
}

void SparseVoxelOctree::push(VkCommandBuffer cmd, const glm::uvec4& args, float cap) const {
    Push push;
    push.args = args;
    push.scale = glm::vec4(float(m_fixedScale), float(1.0 / m_fixedScale),
                           1.0f / std::numbers::pi_v<float>, cap);
    m_layout.push(cmd, push);
}

void SparseVoxelOctree::bindAndDispatch(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline,
                                        const glm::uvec4& args, uint32_t threads, bool voxelSet,
                                        bool photonSet) const {
    bind(cmd, pipeline, voxelSet, photonSet);
    push(cmd, args);
    dispatch(cmd, threads);
}

glm::uvec3 SparseVoxelOctree::dispatchGroups(uint64_t threads, uint32_t groupSize, uint32_t maxX,
                                             uint32_t maxY) {
    if (threads == 0) return glm::uvec3(0);
    if (groupSize == 0 || maxX == 0 || maxY == 0)
        throw Error("SparseVoxelOctree::dispatchGroups: zero group size or limit");
    const uint64_t groups = (threads + groupSize - 1) / groupSize;
    const uint64_t x = std::min<uint64_t>(groups, maxX);
    const uint64_t y = (groups + x - 1) / x;
    if (y > maxY)
        throw Error("SparseVoxelOctree: " + std::to_string(threads) +
                    " threads exceed the device's compute work-group counts");
    return glm::uvec3(uint32_t(x), uint32_t(y), 1u);
}

void SparseVoxelOctree::dispatch(VkCommandBuffer cmd, uint64_t threads) const {
    const glm::uvec3 g = dispatchGroups(threads, kGroupSize, m_maxGroups.x, m_maxGroups.y);
    if (g.x > 0) vkCmdDispatch(cmd, g.x, g.y, g.z);
}

void SparseVoxelOctree::transfer(VkCommandBuffer cmd, uint32_t depth, uint32_t target) const {
    const uint32_t threads = m_info.depthInfo[depth].z;
    for (uint32_t axis = 0; axis < 3; ++axis) {
        for (uint32_t pass = 0; pass < 2; ++pass) {
            bindAndDispatch(cmd, m_transfer, {depth, axis, pass, target}, threads, false, false);
            vk::memoryBarrier(cmd);
        }
    }
}

void SparseVoxelOctree::filterUp(VkCommandBuffer cmd, uint32_t target) const {
    // Radiance of an anisotropic octree: six directional bricks per inner node.
    const bool directional = target == kRadiance && m_anisotropic;
    const uint32_t written = directional ? uint32_t(kDirectional) : target;
    for (int d = int(m_leafDepth) - 1; d >= 0; --d) {
        const uint32_t depth = uint32_t(d);
        bindAndDispatch(cmd, directional ? m_filterAniso : m_filter, {depth, 0, 0, written},
                        uint64_t(m_info.depthInfo[depth].z) * kBrickSamples, false, false);
        vk::memoryBarrier(cmd);
        transfer(cmd, depth, written);
    }
}

void SparseVoxelOctree::build(TechniqueContext& ctx, VkCommandBuffer cmd, VoxelVolumes& voxels) {
    PassScope pass(ctx, cmd, "svo_build");
    if (voxels.albedoOpacity.layout() != VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        voxels.albedoOpacity.transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    if (voxels.normal.layout() != VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL)
        voxels.normal.transition(cmd, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    if (m_voxelView != voxels.albedoOpacity.view() || m_normalView != voxels.normal.view()) {
        m_voxelView = voxels.albedoOpacity.view();
        m_normalView = voxels.normal.view();
        m_voxelSet.writeSampledImage(0, m_voxelView, m_sampler.handle());
        m_voxelSet.writeSampledImage(1, m_normalView, m_sampler.handle());
    }
    m_radiance.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    m_geometry.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    m_normals.transition(cmd, VK_IMAGE_LAYOUT_GENERAL);
    vkCmdFillBuffer(cmd, m_counters.handle(), 0, VK_WHOLE_SIZE, 0);
    vkCmdFillBuffer(cmd, m_occupancy.handle(), 0, VK_WHOLE_SIZE, 0);
    vk::memoryBarrier(cmd);
    const uint32_t head[6] = {1, 0, 0, 0, 0, 1};  // 1 node allocated; depth 0 = [0, 1)
    vkCmdUpdateBuffer(cmd, m_counters.handle(), 0, sizeof(head), head);
    uint32_t root[kNodeWords] = {0,     kNone, kNone, kNone, kNone, kNone,
                                 kNone, kNone, kNone, 0,     0,     kNone};
    vkCmdUpdateBuffer(cmd, m_nodes.handle(), 0, sizeof(root), root);
    vk::memoryBarrier(cmd);

    const uint32_t leafCells = m_info.depthInfo[m_leafDepth].y;
    bindAndDispatch(cmd, m_occupancyLeaf, {m_leafDepth, 0, 0, 0},
                    uint64_t(leafCells) * leafCells * leafCells, true, false);
    vk::memoryBarrier(cmd);
    for (int d = int(m_leafDepth) - 1; d >= 0; --d) {
        const uint32_t cn = m_info.depthInfo[d].y;
        bindAndDispatch(cmd, m_occupancyUp, {uint32_t(d), 0, 0, 0}, uint64_t(cn) * cn * cn, false,
                        false);
        vk::memoryBarrier(cmd);
    }
    // Top-down: flag, allocate tiles and bricks, initialise (notes 001 §2.2 [C]).
    for (uint32_t d = 0; d <= m_leafDepth; ++d) {
        const VkBufferCopy begin{0, VkDeviceSize(4 * (4 + 2 * (d + 1))), 4};
        if (d < m_leafDepth)
            vkCmdCopyBuffer(cmd, m_counters.handle(), m_counters.handle(), 1, &begin);
        vk::memoryBarrier(cmd);
        bindAndDispatch(cmd, m_buildLevel, {d, 0, 0, 0}, m_info.depthInfo[d].z, false, false);
        vk::memoryBarrier(cmd);
        const VkBufferCopy end{0, VkDeviceSize(4 * (5 + 2 * (d + 1))), 4};
        if (d < m_leafDepth)
            vkCmdCopyBuffer(cmd, m_counters.handle(), m_counters.handle(), 1, &end);
        vk::memoryBarrier(cmd);
    }
    for (uint32_t d = 0; d <= m_leafDepth; ++d)
        bindAndDispatch(cmd, m_neighbours, {d, 0, 0, 0}, m_info.depthInfo[d].z, false, false);
    vk::memoryBarrier(cmd);
    bindAndDispatch(cmd, m_leafGeometry, {m_leafDepth, 0, 0, 0},
                    uint64_t(m_info.depthInfo[m_leafDepth].z) * kBrickSamples, true, false);
    vk::memoryBarrier(cmd);
    filterUp(cmd, kGeometry);
}

void SparseVoxelOctree::inject(TechniqueContext& ctx, VkCommandBuffer cmd,
                               const PhotonSource& photons) {
    if (!photons.buffer || !photons.buffer->valid())
        throw Error("SparseVoxelOctree::inject: no photon buffer");
    if (m_photonBuffer != photons.buffer->handle()) {
        m_photonBuffer = photons.buffer->handle();
        m_photonSet.writeBuffer(0, *photons.buffer);
    }
    {
        // techniques/vct/svo.md "Injection": each light's photon range, then per light the
        // deposit counts and the mean irradiance (E / count per deposit) into the canonical leaf
        // copies.
        PassScope pass(ctx, cmd, "svo_inject");
        vkCmdFillBuffer(cmd, m_accum.handle(), 0, VK_WHOLE_SIZE, 0);
        vkCmdFillBuffer(cmd, m_lights.handle(), 0, VK_WHOLE_SIZE, 0);
        vk::memoryBarrier(cmd);
        bindAndDispatch(cmd, m_lightRanges, {photons.count, m_lightCount, 0, m_maxGroups.x},
                        photons.count, false, true);
        vk::memoryBarrier(cmd);
        bindAndDispatch(cmd, m_lightRanges, {photons.count, m_lightCount, 1, m_maxGroups.x},
                        m_lightCount, false, true);
        vk::memoryBarrier(cmd);
        bind(cmd, m_splat, false, true);
        for (uint32_t l = 0; l < m_lightCount; ++l) {
            const float cap = m_floatAtomics ? 0.0f : m_irradianceCaps[l];
            vkCmdFillBuffer(cmd, m_count.handle(), 0, VK_WHOLE_SIZE, 0);
            vk::memoryBarrier(cmd);
            const VkDeviceSize args = VkDeviceSize(l) * kLightWords * 4;
            push(cmd, {l, photons.count, kSplatCount, 0}, cap);
            vkCmdDispatchIndirect(cmd, m_lights.handle(), args);
            vk::memoryBarrier(cmd);
            push(cmd, {l, photons.count, kSplatIrradiance, 0}, cap);
            vkCmdDispatchIndirect(cmd, m_lights.handle(), args);
            vk::memoryBarrier(cmd);
        }
    }
    {
        PassScope pass(ctx, cmd, "svo_transfer");
        transfer(cmd, m_leafDepth, kAccum);
        bindAndDispatch(cmd, m_shade, {m_leafDepth, 0, 0, 0},
                        uint64_t(m_info.depthInfo[m_leafDepth].z) * kBrickSamples, false, false);
        vk::memoryBarrier(cmd);
    }
    {
        PassScope pass(ctx, cmd, "svo_filter");
        filterUp(cmd, kRadiance);
    }
}

void SparseVoxelOctree::updateLights(TechniqueContext& ctx) {
    // Lights as LightInjection numbers them (photon irradiance.w), and the fixed-point scale of
    // the irradiance sums as the dense path: each light's photon E is clamped to its cap (E at
    // v0 / 2 from a pinhole light, E_perp for directional), the caps' sum fits 2^31 units.
    const std::vector<GpuLightView> views =
        buildLightViews(ctx.scene, m_grid, ctx.shared.shadows().emitterSamples());
    const uint32_t lights = views.empty() ? 1u : views.back().group.x + 1u;
    if (m_lights.valid() && lights != m_lightCount)
        throw Error("SparseVoxelOctree::updateLights: the number of lights changed");
    m_lightCount = lights;
    m_irradianceCaps.assign(m_lightCount, 0.0f);
    const double rCap = 0.5 * double(m_grid.voxelSize());
    for (const GpuLightView& v : views) {
        const double i = std::max({v.intensity.x, v.intensity.y, v.intensity.z});
        const double cap = v.positionKind.w > 0.5f ? i : i / (rCap * rCap);
        float& c = m_irradianceCaps[v.group.x];
        c = float(std::max(double(c), cap));
    }
    double bound = 0.0;
    for (float c : m_irradianceCaps)
        bound += double(c);
    if (bound > 0.0) m_fixedScale = 2.0e9 / bound;
    // The photon buffer may have been reallocated (a handle can be reused): rebind on inject
    m_photonBuffer = VK_NULL_HANDLE;
}

void SparseVoxelOctree::addLayoutBindings(std::vector<VkDescriptorSetLayoutBinding>& out,
                                          uint32_t first, VkShaderStageFlags stages) {
    out.push_back({first, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, stages, nullptr});
    out.push_back({first + 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr});
    out.push_back({first + 2, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, stages, nullptr});
    out.push_back({first + 3, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, stages, nullptr});
}

void SparseVoxelOctree::writeDescriptors(vk::DescriptorSet& set, uint32_t first) const {
    set.writeUniformBuffer(first, m_infoBuffer);
    set.writeBuffer(first + 1, m_nodes);
    set.writeSampledImage(first + 2, m_radiance.view(), m_sampler.handle(),
                          VK_IMAGE_LAYOUT_GENERAL);
    set.writeSampledImage(first + 3, m_normals.view(), m_sampler.handle(), VK_IMAGE_LAYOUT_GENERAL);
}

SparseVoxelOctree::Memory SparseVoxelOctree::memory() const {
    Memory m;
    m.nodeCount = m_nodeCapacity;
    m.brickCount = m_brickCapacity;
    m.radianceCount = m_radianceCapacity;
    m.nodeBytes = size_t(m_nodeCapacity) * kNodeBytes;
    auto bytes = [](const vk::Image& image) {
        return size_t(image.desc().width) * image.desc().height * image.desc().depth * 8;
    };
    m.geometryBytes = bytes(m_geometry);
    m.radianceBytes = bytes(m_radiance);
    m.normalBytes = bytes(m_normals) / 2;  // 4 bytes per texel
    m.brickBytes = m.geometryBytes + m.radianceBytes + m.normalBytes;
    m.scratchBytes = size_t(m_accum.size() + m_count.size() + m_lights.size() + m_occupancy.size() +
                            m_counters.size() + m_infoBuffer.size());
    return m;
}

SparseVoxelOctree::Memory SparseVoxelOctree::usedMemory() const {
    std::vector<uint32_t> c = const_cast<vk::Buffer&>(m_counters).downloadVector<uint32_t>(4);
    if (c[2] != 0)
        throw Error("SparseVoxelOctree: pool overflow (flags " + std::to_string(c[2]) + ")");
    Memory m;
    m.nodeCount = c[0];
    m.brickCount = c[1];
    m.radianceCount = c[3];
    m.nodeBytes = size_t(c[0]) * kNodeBytes;
    m.geometryBytes = size_t(c[1]) * kBrickBytes;
    m.radianceBytes = size_t(c[3]) * kBrickBytes;
    m.normalBytes = size_t(c[1]) * kNormalBrickBytes;
    m.brickBytes = m.geometryBytes + m.radianceBytes + m.normalBytes;
    return m;
}

std::vector<uint32_t> SparseVoxelOctree::readNodes() const {
    return const_cast<vk::Buffer&>(m_nodes).downloadVector<uint32_t>(size_t(m_nodeCapacity) *
                                                                     kNodeWords);
}

namespace {
std::vector<glm::vec4> toVec4(const std::vector<float>& f) {
    std::vector<glm::vec4> v(f.size() / 4);
    for (size_t i = 0; i < v.size(); ++i)
        v[i] = glm::vec4(f[4 * i], f[4 * i + 1], f[4 * i + 2], f[4 * i + 3]);
    return v;
}
}  // namespace

std::vector<glm::vec4> SparseVoxelOctree::readRadianceBricks() const {
    return toVec4(const_cast<vk::Image&>(m_radiance).readbackFloat(*m_vk));
}

std::vector<glm::vec4> SparseVoxelOctree::readGeometryBricks() const {
    return toVec4(const_cast<vk::Image&>(m_geometry).readbackFloat(*m_vk));
}

std::vector<glm::vec4> SparseVoxelOctree::readNormalBricks() const {
    const std::vector<uint8_t> raw = const_cast<vk::Image&>(m_normals).readback(*m_vk);
    std::vector<glm::vec4> v(raw.size() / 4);
    auto snorm = [](uint8_t b) { return std::max(float(int8_t(b)) / 127.0f, -1.0f); };
    for (size_t i = 0; i < v.size(); ++i)
        v[i] = glm::vec4(snorm(raw[4 * i]), snorm(raw[4 * i + 1]), snorm(raw[4 * i + 2]),
                         snorm(raw[4 * i + 3]));
    return v;
}

glm::uvec3 SparseVoxelOctree::brickTexel(uint32_t brick, glm::uvec3 s) const {
    const uint32_t bx = m_info.dims.z, by = m_info.capacity.w;
    return 3u * glm::uvec3(brick % bx, (brick / bx) % by, brick / (bx * by)) + s;
}

glm::uvec3 SparseVoxelOctree::radianceTexel(uint32_t slot, glm::uvec3 s) const {
    const uint32_t bx = m_info.radiance.y, by = m_info.radiance.z;
    return 3u * glm::uvec3(slot % bx, (slot / bx) % by, slot / (bx * by)) + s;
}

size_t SparseVoxelOctree::poolTexelIndex(glm::uvec3 t, bool radiance) const {
    const vk::ImageDesc& d = radiance ? m_radiance.desc() : m_geometry.desc();
    return t.x + size_t(d.width) * (t.y + size_t(d.height) * t.z);
}

}  // namespace gilab::vct
