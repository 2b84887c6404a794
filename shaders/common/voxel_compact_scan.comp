#version 460
#extension GL_GOOGLE_include_directive : require
// Compaction pass 2 (one workgroup): exclusive scan of the block counts, total at [blockCount].
#include "common/voxel_compact.glsl"

void main() {
    uint lid = gl_LocalInvocationID.x;
    uint perThread = (pc.blockCount + VOXEL_COMPACT_THREADS - 1u) / VOXEL_COMPACT_THREADS;
    uint first = lid * perThread;
    uint sum = 0u;
    for (uint k = 0u; k < perThread; ++k)
        if (first + k < pc.blockCount) sum += blocks[first + k];
    uint total;
    uint offset = workgroupExclusiveScan(sum, total);
    for (uint k = 0u; k < perThread; ++k) {
        if (first + k >= pc.blockCount) break;
        uint count = blocks[first + k];
        blocks[first + k] = offset;
        offset += count;
    }
    if (lid == 0u) blocks[pc.blockCount] = total;
}
