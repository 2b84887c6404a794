#pragma once
/**
 * Prefix-sum compaction of the voxel buffer (Cosin Ayerbe & Patow 2022 §4.1, Fig. 4): from the N^3
 * list heads of VoxelFragmentLists to per-occupied-voxel arrays in ascending linear-index order:
 *   fragmentIndex[i]   the head of voxel i's fragment list
 *   hashedPosition[i]  its linear index x + N (y + N z) (sorted, as a scan keeps order)
 *   voxelIndex[h]      the inverse, a dense N^3 map (kVoxelListEnd where empty). The paper binary-
 *                      searches hashedPosition instead; the dense map is the notes' §2.1 choice.
 * Passes (shaders/common/voxel_compact_*.comp): per-block counts, one-workgroup scan of the block
 * counts, fill. The occupied count is read back between the scan and the fill, to size the
 * outputs; record both halves with run().
 */
#include <cstdint>
#include <vector>

#include "core/vk/buffer.h"
#include "core/vk/descriptors.h"
#include "core/vk/pipeline.h"
#include "core/voxel/voxel_grid.h"

namespace gilab {
namespace vk {
class Context;
}

class VoxelCompaction {
public:
    VoxelCompaction(vk::Context& ctx, const VoxelGrid& grid, const vk::Buffer& heads);
    VoxelCompaction(const VoxelCompaction&) = delete;
    VoxelCompaction& operator=(const VoxelCompaction&) = delete;

    /** Counts and scans (pass 1-2); after it finished, occupied() reads the total. */
    void recordScan(VkCommandBuffer cmd);
    uint32_t readOccupied();
    /** Allocates the outputs for `occupied` voxels and records the fill (pass 3). */
    void recordFill(VkCommandBuffer cmd, uint32_t occupied);

    uint32_t occupied() const { return m_occupied; }
    vk::Buffer& fragmentIndex() { return m_fragmentIndex; }
    vk::Buffer& hashedPosition() { return m_hashedPosition; }
    vk::Buffer& voxelIndex() { return m_voxelIndex; }
    /** Frees the temporaries the later passes do not need (fragment heads are the caller's). */
    void releaseTemporaries() { m_blocks = vk::Buffer(); }

private:
    struct Push {
        uint32_t voxelCount, blockCount;
    };
    /** Binds `set` at 0 and pushes the counts (every pass has the same push block). */
    void bind(VkCommandBuffer cmd, const vk::PipelineLayout& layout,
              const vk::DescriptorSet& set) const;

    vk::Context& m_ctx;
    VoxelGrid m_grid;
    const vk::Buffer& m_heads;
    uint32_t m_blockCount = 0;
    uint32_t m_occupied = 0;
    vk::Buffer m_blocks, m_fragmentIndex, m_hashedPosition, m_voxelIndex;
    vk::DescriptorSetLayout m_scanLayout, m_fillLayout;
    vk::DescriptorSet m_scanSet, m_fillSet;
    vk::PipelineLayout m_scanPipelineLayout, m_fillPipelineLayout;
    vk::ComputePipeline m_count, m_scan, m_fill;
};

}  // namespace gilab
