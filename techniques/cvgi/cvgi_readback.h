#pragma once
/** The compacted voxelization read back to the host for cvgi's CPU set-up passes. */
#include <cstdint>

#include "core/voxel/voxel_grid.h"
#include "cvgi_voxels.h"

namespace gilab {

class VoxelCompaction;
class VoxelFragmentLists;

/** Walks every occupied voxel's fragment list (§4.1): mean albedo, mean normal and the fragment
 *  normals (blocking reads of the compacted arrays and of `fragmentCount` fragments). */
cvgi::CompactVoxels readCompactVoxels(const VoxelGrid& grid, VoxelCompaction& compaction,
                                      VoxelFragmentLists& lists, uint32_t fragmentCount);

}  // namespace gilab
