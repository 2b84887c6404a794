#version 460
#extension GL_GOOGLE_include_directive : require
// Debug view of the voxel volumes (core/voxel/voxel_debug_view.h): one ray per pixel marched
// through the grid voxel by voxel (Amanatides & Woo 1987 DDA); the first covered voxel
// (albedoOpacity.a > 0) gives the colour: mode 0 albedo, 1 normal * 0.5 + 0.5, 2 emission,
// 3 normal length w (grey). Alpha = 1 on a hit, 0 on a miss (colour 0).
#include "common/voxel_grid.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant, std430) uniform VoxelDebugPush {
    mat4 invViewProj;
    vec4 eye;
    VoxelGridInfo grid;
    uvec4 modeSize;  // x mode, y width, z height
}
pc;

layout(set = 0, binding = 0) uniform sampler3D volAlbedoOpacity;
layout(set = 0, binding = 1) uniform sampler3D volNormal;
layout(set = 0, binding = 2) uniform sampler3D volEmission;
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D outImage;

void main() {
    ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
    if (pix.x >= int(pc.modeSize.y) || pix.y >= int(pc.modeSize.z)) return;
    vec2 ndc = (vec2(pix) + 0.5) / vec2(pc.modeSize.yz) * 2.0 - 1.0;
    vec4 farH = pc.invViewProj * vec4(ndc, 1.0, 1.0);
    vec3 o = voxelWorldToGrid(pc.grid, pc.eye.xyz);
    vec3 d = normalize(voxelWorldToGrid(pc.grid, farH.xyz / farH.w) - o);
    float n = float(voxelResolution(pc.grid));
    // Clip the ray to the grid cube [0, n]^3.
    vec3 inv = 1.0 / d;
    vec3 t0 = (vec3(0.0) - o) * inv, t1 = (vec3(n) - o) * inv;
    float tEnter = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    float tExit = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    vec4 result = vec4(0.0);
    if (tEnter < tExit) {
        vec3 p = o + d * (tEnter + 1e-4);
        ivec3 c = clamp(ivec3(floor(p)), ivec3(0), ivec3(int(n) - 1));
        ivec3 stepDir = ivec3(sign(d));
        vec3 tDelta = abs(inv);
        vec3 next = vec3(c) + max(vec3(stepDir), vec3(0.0));
        vec3 tMax = (next - p) * inv;
        tMax = mix(tMax, vec3(1e30), equal(d, vec3(0.0)));
        for (int i = 0; i < 3 * int(n) + 3; ++i) {
            if (!voxelInside(pc.grid, c)) break;
            vec4 a = texelFetch(volAlbedoOpacity, c, 0);
            if (a.a > 0.0) {
                vec4 nr = texelFetch(volNormal, c, 0);
                uint mode = pc.modeSize.x;
                vec3 col = mode == 0u   ? a.rgb
                           : mode == 1u ? nr.xyz * 0.5 + 0.5
                           : mode == 2u ? texelFetch(volEmission, c, 0).rgb
                                        : vec3(nr.w);
                result = vec4(col, 1.0);
                break;
            }
            if (tMax.x < tMax.y && tMax.x < tMax.z) {
                c.x += stepDir.x;
                tMax.x += tDelta.x;
            } else if (tMax.y < tMax.z) {
                c.y += stepDir.y;
                tMax.y += tDelta.y;
            } else {
                c.z += stepDir.z;
                tMax.z += tDelta.z;
            }
        }
    }
    imageStore(outImage, pix, result);
}
