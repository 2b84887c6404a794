#version 460
#extension GL_GOOGLE_include_directive : require
// Test of the octree cone sampler (tests/vct_svo_test.cpp): one thread per query, writes
// voxelConeSample(position.xyz, position.w = lod, direction.xyz) into `results` (query i =
// queries[2i] position + lod, queries[2i + 1] direction). Set 0 = the octree's
// bindings (SparseVoxelOctree::addLayoutBindings(first = 0)), set 1 = queries and results.
#define SVO_SET 0
#define SVO_BINDING 0
#include "vct/svo_sample.glsl"

layout(set = 1, binding = 0, std430) readonly buffer Queries {
    vec4 queries[];
};
layout(set = 1, binding = 1, std430) writeonly buffer Results {
    vec4 results[];
};
layout(push_constant, std430) uniform TestPush {
    uint count;
} pc;
layout(local_size_x = 64) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    results[i] = voxelConeSample(queries[2u * i].xyz, queries[2u * i].w, queries[2u * i + 1u].xyz);
}
