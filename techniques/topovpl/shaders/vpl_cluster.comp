#version 460
#extension GL_GOOGLE_include_directive : require
// The visibility cluster of every VPL (Noël & Biri 2014 §V: "let P be a VPL and C its visibility
// cluster"), by the same lookup as the pixels (cluster_lookup.glsl; ties toward the VPL's
// normal). Invalid VPLs, and VPLs whose point finds no cluster, get 0xFFFFFFFF and light nothing.
#include "common/voxel_grid.glsl"
#include "common/vpl.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer Vpls { Vpl vpls[]; };
layout(set = 0, binding = 1, std430) readonly buffer VoxelClusters { uint voxelCluster[]; };
layout(set = 0, binding = 2, std430) writeonly buffer VplClusters { uint vplCluster[]; };

layout(push_constant, std430) uniform Push {
    VoxelGridInfo grid;
    uint count;
} pc;

#include "cluster_lookup.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    Vpl v = vpls[i];
    uint id = 0xFFFFFFFFu;
    if (v.position.w > 0.5 && vplFinite(v.position.xyz) && vplFinite(v.normal.xyz))
        id = topoSurfaceCluster(pc.grid, v.position.xyz, v.normal.xyz,
                                v.position.xyz + v.normal.xyz);
    vplCluster[i] = id;
}
