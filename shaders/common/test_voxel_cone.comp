#version 460
#extension GL_GOOGLE_include_directive : require
// Test shader (tests/voxel_cone_test.cpp): evaluates cone queries against a VoxelRadiance.
// mode 0 = traceCone, 1 = traceConeOcclusion (result in .a), 2 = voxelConeSample(origin, lod =
// originTanHalf.w, dir), 3 = traceSurfaceCone(surface (origin, normal.xyz), offset normal.w),
// 4 = coneLevel(t = origin.x, tanHalf) in .x.
layout(local_size_x = 64) in;

#include "common/voxel_grid.glsl"

layout(push_constant) uniform Push {
    VoxelGridInfo grid;
    uint anisotropic;
    uint queryCount;
};

VoxelGridInfo voxelConeGrid() { return grid; }
bool voxelConeAnisotropic() { return anisotropic != 0u; }

#define VOXEL_CONE_SET 0
#define VOXEL_CONE_BINDING 0
#include "common/voxel_cone_dense.glsl"

struct ConeQuery {
    vec4 originTanHalf;  // xyz origin (world), w tan(aperture/2) (mode 2: lod)
    vec4 dirMode;        // xyz direction, w mode
    ConeTraceParams params;
    vec4 normal;  // mode 3: xyz surface normal, w origin offset (world)
};
layout(set = 0, binding = 9, std430) readonly buffer Queries { ConeQuery queries[]; };
layout(set = 0, binding = 10, std430) writeonly buffer Results { vec4 results[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= queryCount) return;
    ConeQuery q = queries[i];
    uint mode = uint(q.dirMode.w + 0.5);
    vec4 r;
    if (mode == 0u) {
        r = traceCone(q.originTanHalf.xyz, q.dirMode.xyz, q.originTanHalf.w, q.params);
    } else if (mode == 1u) {
        r = vec4(0.0, 0.0, 0.0,
                 traceConeOcclusion(q.originTanHalf.xyz, q.dirMode.xyz, q.originTanHalf.w, q.params));
    } else if (mode == 2u) {
        r = voxelConeSample(q.originTanHalf.xyz, q.originTanHalf.w, q.dirMode.xyz);
    } else if (mode == 3u) {
        ConeSurface s = ConeSurface(q.originTanHalf.xyz, q.normal.xyz);
        r = traceSurfaceCone(s, q.normal.w, q.dirMode.xyz, q.originTanHalf.w, q.params);
    } else {
        r = vec4(coneLevel(q.originTanHalf.x, q.originTanHalf.w, q.params), 0.0, 0.0, 0.0);
    }
    results[i] = r;
}
