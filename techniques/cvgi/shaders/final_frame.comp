#version 460
#extension GL_GOOGLE_include_directive : require
// Final frame (§4.5): each G-buffer pixel finds its voxel, picks the face most aligned with its
// normal (argmax |n| with its sign) and interpolates that face's filtered irradiance bilinearly
// over the 4 nearest voxels in the face's plane (empty or not yet gathered voxels are skipped and
// the weights renormalised). Indirect radiance = albedo / pi * E (the harness adds direct light).
#include "cvgi_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 1, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 1, binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(set = 1, binding = 3, rgba32f) uniform image2D outIndirect;

bool gathered(uint j) { return j != CVGI_EMPTY && (voxelState[j] & CVGI_PROCESSED) != 0u; }

// A surface on a voxel boundary occupies two layers; the face of the inner one is buried (its
// rays stop at once). Use the outermost occupied voxel along the face direction (up to 2 steps).
uint outermost(ivec3 c, ivec3 step) {
    uint j = cvgiIndexAt(c);
    for (int k = 0; k < 2 && j != CVGI_EMPTY; ++k) {
        uint next = cvgiIndexAt(c + step);
        if (next == CVGI_EMPTY) break;
        c += step;
        j = next;
    }
    return j;
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= int(u.counts.w) || px.y >= int(u.options.w)) return;
    vec4 pos = imageLoad(gPosition, px);
    if (pos.w <= 0.0) return;
    vec3 n = imageLoad(gNormal, px).xyz;
    vec3 albedo = imageLoad(gAlbedo, px).rgb;
    vec3 g = voxelWorldToGrid(u.grid, pos.xyz);
    vec3 a = abs(n);
    uint axis = a.x >= a.y && a.x >= a.z ? 0u : (a.y >= a.z ? 1u : 2u);
    uint face = 2u * axis + (n[axis] > 0.0 ? 1u : 0u);
    // The fragment's voxel; round-off may put a surface point just outside its voxel.
    ivec3 c = ivec3(floor(g));
    ivec3 step = ivec3(0);
    step[axis] = n[axis] > 0.0 ? 1 : -1;
    if (cvgiIndexAt(c) == CVGI_EMPTY) {
        if (cvgiIndexAt(c - step) != CVGI_EMPTY) c -= step;
        else if (cvgiIndexAt(c + step) != CVGI_EMPTY) c += step;
    }
    uint self = outermost(c, step);
    vec3 e = vec3(0.0);
    if (u.options.z != 0u) {
        uint a1 = (axis + 1u) % 3u, a2 = (axis + 2u) % 3u;
        vec2 t = vec2(g[a1], g[a2]) - 0.5;
        vec2 base = floor(t), fr = t - base;
        vec3 sum = vec3(0.0);
        float weight = 0.0;
        for (int k = 0; k < 4; ++k) {
            ivec3 cc = c;
            cc[a1] = int(base.x) + (k & 1);
            cc[a2] = int(base.y) + (k >> 1);
            uint j = outermost(cc, step);
            if (!gathered(j)) continue;
            float w = ((k & 1) != 0 ? fr.x : 1.0 - fr.x) * ((k >> 1) != 0 ? fr.y : 1.0 - fr.y);
            sum += w * faceFiltered[6u * j + face].rgb;
            weight += w;
        }
        if (weight > 1e-6) e = sum / weight;
        else if (gathered(self)) e = faceFiltered[6u * self + face].rgb;
        else atomicAdd(counters[CVGI_COUNT_UNRESOLVED], 1u);
    } else if (gathered(self)) {
        e = faceFiltered[6u * self + face].rgb;
    } else {
        atomicAdd(counters[CVGI_COUNT_UNRESOLVED], 1u);
    }
    imageStore(outIndirect, px, vec4(albedo * e / 3.14159265358979, 1.0));
}
