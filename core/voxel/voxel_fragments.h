#pragma once
/**
 * Per-voxel fragment lists (Cosin Ayerbe & Patow 2022 §4.1, Fig. 3), filled by the Voxelizer
 * when VoxelizerOptions::fragmentCapacity > 0: a linear fragment buffer (world position, normal,
 * albedo, next) appended with an atomic counter, and the "voxel buffer" of N^3 list heads (the
 * paper's collision-free hash = our linear index x + N (y + N z)). VoxelCompaction turns the heads
 * into compacted per-occupied-voxel arrays with a prefix sum.
 * Shader side: shaders/common/voxel_fragments.glsl (set 2 of the voxelize pipeline).
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/voxel/voxel_grid.h"

namespace gilab {
namespace vk {
class Context;
}

inline constexpr uint32_t kVoxelListEnd = 0xFFFFFFFFu;

/** Mirrors VoxelFragment in shaders/common/voxel_fragments.glsl (32 bytes). */
struct GpuVoxelFragment {
    glm::vec3 position;  // world
    uint32_t next;       // kVoxelListEnd at the tail
    uint32_t normalOct;  // packSnorm2x16(octahedral normal)
    uint32_t albedoLo;   // packHalf2x16(r, g)
    uint32_t albedoHi;   // packHalf2x16(b, 0)
    uint32_t pad;
};
static_assert(sizeof(GpuVoxelFragment) == 32);

/** Decoded fragment attributes. */
glm::vec3 fragmentNormal(const GpuVoxelFragment& f);
glm::vec3 fragmentAlbedo(const GpuVoxelFragment& f);

class VoxelFragmentLists {
public:
    VoxelFragmentLists(vk::Context& ctx, const VoxelGrid& grid, uint32_t capacity);
    VoxelFragmentLists(const VoxelFragmentLists&) = delete;
    VoxelFragmentLists& operator=(const VoxelFragmentLists&) = delete;

    /** Heads to kVoxelListEnd, counter to 0 (recorded before the voxelize draw). */
    void recordClear(VkCommandBuffer cmd);
    /** Fragments the last run produced (blocking read of the counter). */
    uint32_t written();
    bool overflowed() { return written() > m_capacity; }
    /** A new fragment buffer with room for `capacity` (throws a clear gilab::Error above the
     *  device's maxStorageBufferRange). The next run must start from recordClear(). */
    void grow(uint32_t capacity);
    uint32_t capacity() const { return m_capacity; }

    const vk::DescriptorSetLayout& layout() const { return m_layout; }
    const vk::DescriptorSet& set() const { return m_set; }
    vk::Buffer& heads() { return m_heads; }          // [N^3] first fragment of each voxel
    vk::Buffer& fragments() { return m_fragments; }  // [capacity] GpuVoxelFragment
    /** The first `count` fragments (blocking). */
    std::vector<GpuVoxelFragment> readFragments(uint32_t count);
    /** Frees the fragment buffer (the heads stay for VoxelCompaction). */
    void releaseFragments();

private:
    void allocateFragments(uint32_t capacity);

    vk::Context& m_ctx;
    VoxelGrid m_grid;
    uint32_t m_capacity = 0;
    vk::Buffer m_heads, m_fragments, m_counter;
    vk::DescriptorSetLayout m_layout;
    vk::DescriptorSet m_set;
};

}  // namespace gilab
