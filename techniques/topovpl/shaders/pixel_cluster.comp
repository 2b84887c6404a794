#version 460
#extension GL_GOOGLE_include_directive : require
// The visibility cluster of every G-buffer pixel (Noël & Biri 2014 §V-A; techniques/topovpl/
// pixel_clusters.h), through topoSurfaceCluster (ties at corners toward the viewer). Writes the
// id (0xFFFFFFFF: none) and a debug colour (clusterColour in topology_export.cpp).
#include "common/voxel_grid.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 0, binding = 2, std430) readonly buffer VoxelClusters { uint voxelCluster[]; };
layout(set = 0, binding = 3, r32ui) uniform writeonly uimage2D clusterImage;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D debugImage;

layout(push_constant, std430) uniform Push {
    VoxelGridInfo grid;
    vec4 eye;  // xyz the viewer: ties between equally normal-facing neighbours go its way
} pc;

#include "cluster_lookup.glsl"

vec3 clusterColour(uint c) {
    float h = fract(0.618034 * float(c)) * 6.0;
    float x = 1.0 - abs(mod(h, 2.0) - 1.0);
    int sector = int(h) % 6;
    vec3 rgb = sector == 0 ? vec3(1, x, 0) : sector == 1 ? vec3(x, 1, 0)
             : sector == 2 ? vec3(0, 1, x) : sector == 3 ? vec3(0, x, 1)
             : sector == 4 ? vec3(x, 0, 1) : vec3(1, 0, x);
    return 0.2 + 0.8 * rgb;
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(gPosition)))) return;
    vec4 p = imageLoad(gPosition, px);
    uint id = 0xFFFFFFFFu;
    if (p.w > 0.5) id = topoSurfaceCluster(pc.grid, p.xyz, imageLoad(gNormal, px).xyz, pc.eye.xyz);
    imageStore(clusterImage, px, uvec4(id));
    imageStore(debugImage, px, vec4(id == 0xFFFFFFFFu ? vec3(0.0) : clusterColour(id), 1.0));
}
