#version 460
#extension GL_GOOGLE_include_directive : require
// Test of the octree cone sampler (techniques/vct/tests/vct_svo_test.cpp): one thread per query i
// (queries[2i] = position.xyz + w, queries[2i + 1] = direction.xyz + w). direction.w = 0:
// voxelConeSample(position, lod = position.w, direction); direction.w > 0: traceCone from
// position along direction with tan(aperture / 2) = direction.w (step factor 0.5, no lift, the
// whole grid). Result into `results`. Set 0 = the octree's bindings
// (SparseVoxelOctree::addLayoutBindings(first = 0)), set 1 = queries and results.
#define SVO_SET 0
#define SVO_BINDING 0
#include "svo_sample.glsl"

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
    vec4 q = queries[2u * i], d = queries[2u * i + 1u];
    if (d.w > 0.0) {
        float v0 = svoInfo.originVoxelSize.w;
        float side = v0 * float(svoInfo.dims.x);
        ConeTraceParams p;
        p.gridMinV0 = svoInfo.originVoxelSize;
        p.gridMaxStep = vec4(svoInfo.originVoxelSize.xyz + side, 0.5);
        p.distances = vec4(2.0 * side, 0.0, 1.0, 0.0);
        p.misc = vec4(0.0);
        results[i] = traceCone(q.xyz, d.xyz, d.w, p);
    } else {
        results[i] = voxelConeSample(q.xyz, q.w, d.xyz);
    }
}
