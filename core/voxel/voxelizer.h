#pragma once
/**
 * Static GPU voxelization of a GpuScene into dense 3D volumes (docs/voxelization.md), shared by
 * voxel cone tracing (notes 001 §2.2), deferred voxel shading (notes 003 §2.1) and clustered
 * voxel GI. Two passes, both recorded by record():
 *   "voxelize"       one draw of every triangle with no attachments at an N x N viewport:
 *                    dominant-axis projection + conservative coverage (geometry shader
 *                    dilation, exact triangle/voxel test per voxel), atomic sums per voxel
 *   "voxel_resolve"  compute: sums / count -> albedoOpacity, normal, emission
 * Sums use float atomics when the device has them (Context::hasFloatAtomics), else fixed-point
 * uint atomics (scales and overflow bounds in shaders/common/voxel_grid.glsl).
 * Memory is tagged "voxel/...". After record() the volumes are SHADER_READ_ONLY_OPTIMAL.
 * In fragment-list mode (fragmentCapacity > 0) the voxelize pass instead appends every voxel
 * fragment to per-voxel linked lists (clustered voxel GI §4.1; core/voxel/voxel_fragments.h);
 * there are no volumes then (volumes() is empty, readVoxels() throws).
 */
#include <cstdint>
#include <memory>
#include <vector>

#include <vulkan/vulkan.h>
#include <glm/glm.hpp>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/image.h"
#include "core/vk/pipeline.h"
#include "core/voxel/voxel_fragments.h"
#include "core/voxel/voxel_grid.h"

namespace gilab {
namespace vk {
class Context;
class GpuScene;
class GpuTimer;
}  // namespace vk

struct VoxelizerOptions {
    bool fullPrecision = false;    // RGBA32F volumes instead of RGBA16F
    bool forceFixedPoint = false;  // uint accumulators even with float atomics (tests)
    /** > 0: fragment-list mode: build per-voxel fragment lists (VoxelFragmentLists) with room
     *  for this many fragments, and no accumulators, volumes or resolve pass (the lists carry
     *  every fragment). run() grows the buffer and voxelizes again when a scene needs more. */
    uint32_t fragmentCapacity = 0;
};

/** The final volumes, resolution^3 each (contents in shaders/common/voxel_resolve_body.glsl). */
struct VoxelVolumes {
    vk::Image albedoOpacity;  // rgb average linear albedo, a = 1 covered / 0 empty
    vk::Image normal;         // xyz normalised average normal, w = its length before (0 = none)
    vk::Image emission;       // rgb average emitted radiance, a = 1 covered / 0 empty
};

/** CPU copy of the volumes, x + N (y + N z) order. */
struct VoxelData {
    uint32_t resolution = 0;
    std::vector<glm::vec4> albedoOpacity, normal, emission;
    std::vector<uint32_t> count;  // fragments accumulated per voxel

    size_t index(const glm::ivec3& c) const {
        return size_t(c.x) + resolution * (size_t(c.y) + size_t(resolution) * size_t(c.z));
    }
    size_t occupiedCount() const;
};

class Voxelizer {
public:
    Voxelizer(vk::Context& ctx, const vk::GpuScene& scene, const VoxelGrid& grid,
              const VoxelizerOptions& options = {});
    Voxelizer(const Voxelizer&) = delete;
    Voxelizer& operator=(const Voxelizer&) = delete;

    /** Clears the accumulators, voxelizes the scene and resolves; timed as "voxelize" and
     *  "voxel_resolve" when `timer` is given. */
    void record(VkCommandBuffer cmd, vk::GpuTimer* timer = nullptr);
    /** record() in its own submission (blocking). With fragment lists, a second run with a
     *  grown buffer follows when the first overflowed (its time is then counted twice). */
    void run(vk::GpuTimer* timer = nullptr);
    /** Null unless options.fragmentCapacity > 0. After a run that did not overflow, the lists
     *  hold every fragment (fragments()->overflowed() says otherwise). */
    VoxelFragmentLists* fragments() { return m_fragments.get(); }
    /** After a finished run in fragment-list mode that overflowed: grows the buffer to the
     *  counted fragments and returns true (record() must then run again); else false. */
    bool growFragmentsIfOverflowed();

    const VoxelGrid& grid() const { return m_grid; }
    VoxelVolumes& volumes() { return m_volumes; }
    bool usesFloatAtomics() const { return m_floatAtomics; }
    VkFormat volumeFormat() const { return m_format; }
    /** Reads back the volumes and the per-voxel fragment counts (blocking). */
    VoxelData readVoxels();
    /** Frees the accumulators (10 x 4 bytes per voxel) once no more runs or reads are needed. */
    void releaseAccumulators() { m_accumulators.clear(); }

    /** Accumulator planes: albedo rgb, normal xyz, emission rgb, fragment count. */
    static constexpr uint32_t kAccumulatorWords = 10;

private:
    /** Accumulators, volumes and the resolve pass (all but fragment-list mode). */
    void createAccumulation(const VoxelizerOptions& options);

    vk::Context& m_ctx;
    const vk::GpuScene& m_scene;
    VoxelGrid m_grid;
    bool m_floatAtomics = false;
    VkFormat m_format = VK_FORMAT_R16G16B16A16_SFLOAT;
    std::vector<vk::Buffer> m_accumulators;  // one plane of N^3 words each
    std::unique_ptr<VoxelFragmentLists> m_fragments;
    VoxelVolumes m_volumes;
    vk::DescriptorSetLayout m_accumLayout, m_resolveSetLayout;
    vk::DescriptorSet m_accumSet, m_resolveSet;
    vk::PipelineLayout m_voxelizeLayout, m_resolveLayout;
    vk::GraphicsPipeline m_voxelize;
    vk::ComputePipeline m_resolve;
};

}  // namespace gilab
