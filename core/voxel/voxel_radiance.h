#pragma once
/**
 * The filtered radiance pyramid read by voxel cone tracing (docs/voxel_cone_tracing.md).
 *
 * base():  N^3 RGBA16F (RGBA32F with fullPrecision), rgb = outgoing radiance premultiplied by
 *          opacity, a = opacity. Written by the technique (imageStore), always in GENERAL layout.
 * filter(): anisotropic (default): 6 directional volumes -X,+X,-Y,+Y,-Z,+Z at (N/2)^3 with a full
 *          mip chain down to 1^3; each value is the average over the 4 pairs of children along
 *          the face's axis of front + (1 - front.a) back (Crassin §9, notes 003 E5, §7.3).
 *          The six are slabs of one atlas volume (N/2, N/2, 6 N/2) with mips, face f at z in
 *          [f n, (f + 1) n) of each level: a cone picks its face by coordinates, not by a branch
 *          (lavapipe runs both sides of a branch; docs/voxel_cone_tracing.md "Speed").
 *          Isotropic: one (N/2)^3 volume + mips, Box (2x2x2 average) or Gaussian (separable
 *          [1,3,3,1]/8 around the 2x2x2 block, the cell-centred analogue of Crassin §4.2.3).
 *          One compute dispatch per level, each followed by a barrier.
 * Facing (Crassin §7, issue 9): with setSurfaceNormals(), a voxel's radiance is seen only from
 * the side its averaged surface normal faces (shaders/common/voxel_facing.glsl): the directional
 * level 0 is built from facing-weighted children, and base samples are weighted the same way.
 * Without it (or where a voxel has no normal) radiance is isotropic.
 * Shaders read everything through combined image samplers (trilinear, mipmap linear, clamp to
 * transparent-black border), bindings as addLayoutBindings / shaders/common/voxel_cone_dense.glsl.
 * Memory is tagged with the caller's tag ("<tag>/base", "<tag>/face-X", ...).
 */
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/vk/sampler.h"
#include "core/voxel/voxel_grid.h"

namespace gilab {
namespace vk {
class Context;
}

enum class VoxelMipFilter { Box, Gaussian };  // Gaussian = the paper's 3^3 tent (Crassin §4.2.3)

struct VoxelRadianceOptions {
    bool anisotropic = true;  // 6 directional volumes (-X,+X,-Y,+Y,-Z,+Z) at (N/2)^3 + full mips
                              // (Crassin §9, notes 003 E5)
    VoxelMipFilter isotropicFilter = VoxelMipFilter::Gaussian;  // when !anisotropic: one (N/2)^3
                                                                // volume + mips
    bool fullPrecision = false;                                 // RGBA32F instead of RGBA16F
};

class VoxelRadiance {
public:
    static constexpr uint32_t kFaceCount = 6;
    static constexpr uint32_t kBindingCount = 3;  // base, filtered atlas, surface normals

    VoxelRadiance(vk::Context& ctx, const VoxelGrid& grid, const VoxelRadianceOptions& options,
                  const std::string& memoryTag);  // e.g. ctx.tag("radiance")
    VoxelRadiance(const VoxelRadiance&) = delete;
    VoxelRadiance& operator=(const VoxelRadiance&) = delete;

    /** N^3 RGBA16F (or 32F), STORAGE|SAMPLED|TRANSFER_DST, always in VK_IMAGE_LAYOUT_GENERAL.
     *  Techniques write it with imageStore (declare layout(rgba16f) / rgba32f per format()). */
    vk::Image& base() { return m_base; }
    VkFormat format() const { return m_format; }
    /** The voxelizer's averaged-normal volume (N^3, xyz unit, w length; SHADER_READ_ONLY_OPTIMAL
     *  when filtered and traced): radiance then faces its surface's side. Call before filter()
     *  and writeDescriptors(). */
    void setSurfaceNormals(const vk::Image& normals);
    bool hasSurfaceNormals() const { return m_normalView != m_noNormals.view(); }

    /** Zeroes the base volume (transparent black), then a barrier. */
    void clearBase(VkCommandBuffer cmd);
    /** Barrier after the caller's writes to base(), then the mip passes; leaves everything readable
     *  by compute shaders (GENERAL layout, sampled). */
    void filter(VkCommandBuffer cmd);
    /** Pyramid levels including base: log2(N) + 1. */
    uint32_t levels() const;
    size_t memoryBytes() const;
    /** Bytes the pyramid of a grid of resolution n needs (base + filtered volumes with mips). */
    static size_t memoryBytesFor(uint32_t n, const VoxelRadianceOptions& options);
    const VoxelGrid& grid() const { return m_grid; }
    const VoxelRadianceOptions& options() const { return m_options; }

    /** Bindings for shaders/common/voxel_cone_dense.glsl: first = base, first+1 = the filtered
     *  atlas (6 face slabs -X,+X,-Y,+Y,-Z,+Z, or 1 isotropic slab), first+2 = surface normals (a
     *  zero 1^3 volume without setSurfaceNormals). Combined image samplers. */
    static void addLayoutBindings(std::vector<VkDescriptorSetLayoutBinding>& out, uint32_t first,
                                  VkShaderStageFlags stages);
    /** Same bindings in the vk::DescriptorSetLayout form. */
    static void addLayoutBindings(std::vector<vk::DescriptorBinding>& out, uint32_t first,
                                  VkShaderStageFlags stages);
    void writeDescriptors(vk::DescriptorSet& set, uint32_t first) const;
    /** The sampler used for every binding (trilinear, clamp to transparent-black border). */
    VkSampler sampler() const { return m_sampler.handle(); }
    /** Face slabs in the filtered atlas: 6 (anisotropic) or 1 (isotropic). */
    uint32_t slabCount() const { return m_options.anisotropic ? kFaceCount : 1; }

    /** Tests: level 0 = base, level l >= 1 = filtered level l-1 of `face` (0..5; ignored if
     *  isotropic). x + n (y + n z) order. Blocking. */
    std::vector<glm::vec4> readLevel(uint32_t level, int face);

private:
    vk::Context& m_ctx;
    VoxelGrid m_grid;
    VoxelRadianceOptions m_options;
    VkFormat m_format = VK_FORMAT_R16G16B16A16_SFLOAT;
    vk::Image m_base;
    vk::Image m_filtered;  // atlas: slabCount() slabs of (N/2)^3 stacked in z, with mips
    vk::Sampler m_sampler;
    vk::Image m_noNormals;  // 1^3 zero: no facing
    VkImageView m_normalView = VK_NULL_HANDLE;
    VkImageLayout m_normalLayout = VK_IMAGE_LAYOUT_GENERAL;
    vk::DescriptorSetLayout m_setLayout;
    vk::PipelineLayout m_pipelineLayout;
    vk::ComputePipeline m_firstLevel;       // base -> level 0 of the filtered volumes
    vk::ComputePipeline m_nextLevel;        // level l-1 -> level l
    std::vector<vk::DescriptorSet> m_sets;  // one per filtered level (and per face group)
};

}  // namespace gilab
