#version 460
#extension GL_GOOGLE_include_directive : require
// Compaction pass 1: occupied voxels per block (see voxel_compact.glsl).
#include "common/voxel_compact.glsl"

void main() {
    uint first = gl_WorkGroupID.x * VOXEL_COMPACT_BLOCK +
                 gl_LocalInvocationID.x * VOXEL_COMPACT_PER_THREAD;
    uint count = 0u;
    for (uint k = 0u; k < VOXEL_COMPACT_PER_THREAD; ++k) {
        uint i = first + k;
        if (i < pc.voxelCount && heads[i] != VOXEL_COMPACT_EMPTY) ++count;
    }
    uint total;
    workgroupExclusiveScan(count, total);
    if (gl_LocalInvocationID.x == 0u) blocks[gl_WorkGroupID.x] = total;
}
