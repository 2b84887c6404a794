// Prefix-sum compaction of the voxel buffer (core/voxel/voxel_compaction.h; Cosin Ayerbe & Patow
// 2022 §4.1, Fig. 4): three passes over the N^3 list heads in blocks of VOXEL_COMPACT_BLOCK.
#ifndef GILAB_VOXEL_COMPACT_GLSL
#define GILAB_VOXEL_COMPACT_GLSL

#define VOXEL_COMPACT_THREADS 256u
#define VOXEL_COMPACT_PER_THREAD 16u
#define VOXEL_COMPACT_BLOCK (VOXEL_COMPACT_THREADS * VOXEL_COMPACT_PER_THREAD)
#define VOXEL_COMPACT_EMPTY 0xFFFFFFFFu

layout(local_size_x = 256) in;

layout(push_constant, std430) uniform CompactPush {
    uint voxelCount;  // N^3
    uint blockCount;  // ceil(N^3 / VOXEL_COMPACT_BLOCK)
} pc;

layout(set = 0, binding = 0, std430) readonly buffer VoxelHeads {
    uint heads[];
};
// [blockCount + 1]: per-block occupied counts, then (after the scan) exclusive offsets with the
// total at [blockCount].
layout(set = 0, binding = 1, std430) buffer CompactBlocks {
    uint blocks[];
};

shared uint sharedValues[VOXEL_COMPACT_THREADS];

// Exclusive scan of one value per thread across the workgroup; returns the thread's offset and
// leaves the workgroup total in sharedValues[THREADS - 1] + value of the last thread.
uint workgroupExclusiveScan(uint value, out uint total) {
    uint lid = gl_LocalInvocationID.x;
    sharedValues[lid] = value;
    barrier();
    // Hillis-Steele inclusive scan.
    for (uint stride = 1u; stride < VOXEL_COMPACT_THREADS; stride <<= 1u) {
        uint add = lid >= stride ? sharedValues[lid - stride] : 0u;
        barrier();
        sharedValues[lid] += add;
        barrier();
    }
    total = sharedValues[VOXEL_COMPACT_THREADS - 1u];
    return sharedValues[lid] - value;
}

#endif  // GILAB_VOXEL_COMPACT_GLSL
