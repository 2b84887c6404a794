#version 460
#extension GL_GOOGLE_include_directive : require
// Octree build, step 1 (techniques/vct/svo.md): a leaf cell n is occupied when one of the 27
// voxels of its vertex-centred brick (voxel centres 2n .. 2n+2 per axis) is covered
// (albedoOpacity.a).
#include "svo_common.glsl"

layout(set = 1, binding = 0) uniform sampler3D voxelAlbedoOpacity;
layout(local_size_x = SVO_GROUP_SIZE) in;

void main() {
    uint d = svo.dims.y;
    uint n = svo.depthInfo[d].y;
    uint idx = svoThread();
    if (idx >= n * n * n) return;
    uvec3 c = uvec3(idx % n, (idx / n) % n, idx / (n * n));
    int res = int(svo.dims.x);
    bool occupied = false;
    for (int k = 0; k < 27 && !occupied; ++k) {
        ivec3 v = 2 * ivec3(c) + ivec3(k % 3, (k / 3) % 3, k / 9);
        if (any(greaterThanEqual(v, ivec3(res)))) continue;
        occupied = texelFetch(voxelAlbedoOpacity, v, 0).a > 0.0;
    }
    if (occupied) atomicOr(svoOccupancy[svo.depthInfo[d].x + (idx >> 5)], 1u << (idx & 31u));
}
