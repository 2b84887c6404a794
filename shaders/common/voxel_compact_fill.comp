#version 460
#extension GL_GOOGLE_include_directive : require
// Compaction pass 3: each occupied voxel gets its compacted index i (ascending linear index,
// the order a prefix sum keeps): fragmentIndex[i] = list head, hashedPosition[i] = linear index,
// and the dense map voxelIndex[linear] = i (VOXEL_COMPACT_EMPTY where empty).
#include "common/voxel_compact.glsl"

layout(set = 0, binding = 2, std430) writeonly buffer FragmentIndex {
    uint fragmentIndex[];
};
layout(set = 0, binding = 3, std430) writeonly buffer HashedPosition {
    uint hashedPosition[];
};
layout(set = 0, binding = 4, std430) writeonly buffer VoxelIndex {
    uint voxelIndex[];
};

void main() {
    uint first = gl_WorkGroupID.x * VOXEL_COMPACT_BLOCK +
                 gl_LocalInvocationID.x * VOXEL_COMPACT_PER_THREAD;
    uint count = 0u;
    for (uint k = 0u; k < VOXEL_COMPACT_PER_THREAD; ++k) {
        uint i = first + k;
        if (i < pc.voxelCount && heads[i] != VOXEL_COMPACT_EMPTY) ++count;
    }
    uint total;
    uint offset = blocks[gl_WorkGroupID.x] + workgroupExclusiveScan(count, total);
    for (uint k = 0u; k < VOXEL_COMPACT_PER_THREAD; ++k) {
        uint i = first + k;
        if (i >= pc.voxelCount) break;
        uint head = heads[i];
        if (head == VOXEL_COMPACT_EMPTY) {
            voxelIndex[i] = VOXEL_COMPACT_EMPTY;
            continue;
        }
        fragmentIndex[offset] = head;
        hashedPosition[offset] = i;
        voxelIndex[i] = offset;
        ++offset;
    }
}
