#version 460
#extension GL_GOOGLE_include_directive : require
// The visibility cluster of every G-buffer pixel (Noël & Biri 2014 §V-A; techniques/topovpl/
// pixel_clusters.h): world position, moved half a voxel along the normal -> voxel of the
// topology grid -> its cluster. A point in a solid voxel has no cluster: it takes the empty
// voxel on its normal's side, the one of its 26 neighbours whose direction has the largest dot product with
// the normal (ties, at corners: the one toward the viewer). Writes the id (0xFFFFFFFF: none) and a debug
// colour (clusterColour in topology_export.cpp).
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

const uint kNone = 0xFFFFFFFFu;

uint clusterAt(ivec3 c) {
    int n = int(pc.grid.resolution.x);
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(n)))) return kNone;
    return voxelCluster[uint(c.x) + uint(n) * (uint(c.y) + uint(n) * uint(c.z))];
}

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
    uint id = kNone;
    if (p.w > 0.5) {
        vec3 n = imageLoad(gNormal, px).xyz;
        // Half a voxel off the surface along the normal: the point itself lies on a voxel face
        // as often as not, and the voxel behind the surface is not its side.
        vec3 q = p.xyz + n * (0.5 * voxelSize(pc.grid));
        ivec3 v = ivec3(floor(voxelWorldToGrid(pc.grid, q)));
        id = clusterAt(v);
        if (id == kNone) {
            float best = -2.0;
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        ivec3 d = ivec3(dx, dy, dz);
                        if (d == ivec3(0)) continue;
                        uint c = clusterAt(v + d);
                        if (c == kNone) continue;
                        // The normal decides; on a tie (a corner) the side the viewer sees the
                        // point from, which is empty space too.
                        vec3 dir = normalize(vec3(d));
                        float score = dot(dir, n) + 1e-3 * dot(dir, normalize(pc.eye.xyz - p.xyz));
                        if (score > best) {
                            best = score;
                            id = c;
                        }
                    }
        }
    }
    imageStore(clusterImage, px, uvec4(id));
    imageStore(debugImage, px, vec4(id == kNone ? vec3(0.0) : clusterColour(id), 1.0));
}
