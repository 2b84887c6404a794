#version 460
#extension GL_GOOGLE_include_directive : require
// DVS pass L1, per-voxel direct light (notes 003 §2.4), one thread per voxel:
//   base.rgb = a * (rho / pi) * sum_lights E_perp * lambert(N, Psi) * visibility,  base.a = a
// over every entry of the pass light table (scene punctual lights, then the emitter samples
// that stand in for emissive triangles), with E_perp from lights.glsl (our falloff and spot
// cone, not the repo's "+1" attenuation). Position: voxel centre + N v/2 (§7.6).
// Visibility: the shared shadow maps, or a march through the voxel grid (hard, or soft E4).
#include "common/voxel_grid.glsl"
#define SHADOW_SET 0
#define SHADOW_BINDING 3
#include "common/shadow.glsl"
#include "dvs_lambert.glsl"

#define DVS_PI 3.14159265358979323846
#define DVS_SHADOWS_MAP 0u
#define DVS_SHADOWS_RAY 1u
#define DVS_SHADOWS_RAY_SOFT 2u

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(set = 0, binding = 0) uniform sampler3D voxAlbedo;  // rgb albedo, a coverage
layout(set = 0, binding = 1) uniform sampler3D voxNormal;  // xyz unit normal, w length before
layout(set = 0, binding = 2, rgba16f) uniform writeonly image3D outBase;

layout(push_constant, std430) uniform VoxelDirectPush {
    VoxelGridInfo grid;
    vec4 params;  // x soft-shadow kappa, y min light distance (world) for emitter samples
    uvec4 modes;  // x lambert mode, y shadow mode, z light count, w 1 = shadow maps on
} pc;

bool voxelOccupied(ivec3 c) {
    return voxelInside(pc.grid, c) && texelFetch(voxAlbedo, c, 0).a > 0.0;
}

// March the grid from p toward the light (unit dir, grid units = voxels): start at 2 voxels,
// step 1 voxel (notes 003 §2.4, repo), up to maxT voxels. Hard: 0 at the first occupied voxel.
// Soft (E4): nu += (1 - nu) * min(kappa / t, 1) per occupied voxel, t in grid sides (t_voxels / N);
// the min() is the singularity guard (kappa / t > 1 would overshoot nu past 1).
float rayVisibility(vec3 p, vec3 dir, float maxT, bool soft) {
    vec3 g0 = voxelWorldToGrid(pc.grid, p);
    float n = float(voxelResolution(pc.grid));
    float nu = 0.0;
    for (float t = 2.0; t <= maxT; t += 1.0) {
        ivec3 c = ivec3(floor(g0 + dir * t));
        if (!voxelInside(pc.grid, c)) break;
        if (!voxelOccupied(c)) continue;
        if (!soft) return 0.0;
        nu += (1.0 - nu) * min(pc.params.x / (t / n), 1.0);
        if (nu >= 0.999) return 0.0;
    }
    return 1.0 - nu;
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (!voxelInside(pc.grid, c)) return;
    vec4 albedo = texelFetch(voxAlbedo, c, 0);
    if (!(albedo.a > 0.0)) {
        imageStore(outBase, c, vec4(0.0));
        return;
    }
    // Guard the averaged normal: a (near) zero average means opposite faces share the voxel.
    vec4 nl = texelFetch(voxNormal, c, 0);
    float nLen = length(nl.xyz);
    bool hasNormal = nl.w > 1.0e-3 && nLen > 0.5;
    vec3 n = hasNormal ? nl.xyz / nLen : vec3(0.0);

    float v = voxelSize(pc.grid);
    vec3 p = voxelCenterWorld(pc.grid, c) + n * (0.5 * v);
    uint shadowMode = pc.modes.y;

    vec3 irradiance = vec3(0.0);
    for (uint i = 0u; i < pc.modes.z; ++i) {
        PassLight light = passLights[i];
        vec3 wi;
        float dist;
        vec3 ePerp = lightIrradiancePerp(light, p, wi, dist);
        uint type = uint(light.positionType.w);
        // Emitter samples are points on the emitter: floor r at one voxel (techniques/dvs/README.md).
        if (type == PASS_LIGHT_EMITTER_SAMPLE && dist < pc.params.y)
            ePerp *= (dist * dist) / (pc.params.y * pc.params.y);
        if (all(equal(ePerp, vec3(0.0)))) continue;
        float lambert = hasNormal ? dvsLambert(pc.modes.x, n, wi) : DVS_ISOTROPIC_LAMBERT;
        if (!(lambert > 0.0)) continue;

        float visibility = 1.0;
        if (shadowMode == DVS_SHADOWS_MAP) {
            if (pc.modes.w != 0u) {
                vec3 ns = hasNormal ? (dot(n, wi) >= 0.0 ? n : -n) : wi;
                visibility = shadowVisibility(light, p, ns, wi);
            }
        } else {
            // Stop one voxel short of a positional light (its fixture or emitter voxel).
            float maxT = type == PASS_LIGHT_DIRECTIONAL ? 2.0 * float(voxelResolution(pc.grid))
                                                        : dist / v - 1.0;
            visibility = rayVisibility(p, wi, maxT, shadowMode == DVS_SHADOWS_RAY_SOFT);
        }
        irradiance += ePerp * (lambert * visibility);
    }
    vec3 radiance = albedo.a * albedo.rgb * (1.0 / DVS_PI) * irradiance;
    imageStore(outBase, c, vec4(radiance, albedo.a));
}
