#version 460
#extension GL_GOOGLE_include_directive : require
// DVS pass G1, per-voxel first bounce (notes 003 §2.6), one thread per voxel: diffuse cones
// around the voxel's averaged normal through the filtered direct radiance (the pixel cones'
// step, level mapping and lift), then
//   out.rgb = base.rgb + a * (rho / pi) * sum_i w_i L_i   (sum w = pi, E14; HDR, no clamp)
//   out.a   = base.a
// written to a scratch volume (copied over the base afterwards), so the cones may read every
// level including the base. Voxels without a normal keep their direct value.
#include "common/voxel_grid.glsl"
#include "common/cone_set.glsl"

#define DVS_PI 3.14159265358979323846

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(set = 0, binding = 0) uniform sampler3D voxAlbedo;
layout(set = 0, binding = 1) uniform sampler3D voxNormal;
layout(set = 0, binding = 2, rgba16f) uniform writeonly image3D outRadiance;
layout(set = 0, binding = 3, std140) uniform BounceUniforms {
    VoxelGridInfo grid;
    vec4 coneParams[4];  // ConeTraceParams
    vec4 misc;           // x origin offset along the normal (world) from the lift plane
    ConeSetData cones;
} u;

VoxelGridInfo voxelConeGrid() { return u.grid; }
bool voxelConeAnisotropic() { return true; }
#define VOXEL_CONE_SET 0
#define VOXEL_CONE_BINDING 4
#include "common/voxel_cone_dense.glsl"

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (!voxelInside(u.grid, c)) return;
    vec4 direct = texelFetch(voxelConeBase, c, 0);
    vec4 albedo = texelFetch(voxAlbedo, c, 0);
    vec4 nl = texelFetch(voxNormal, c, 0);
    float nLen = length(nl.xyz);
    if (!(albedo.a > 0.0) || !(nl.w > 1.0e-3) || !(nLen > 0.5)) {
        imageStore(outRadiance, c, direct);
        return;
    }
    vec3 n = nl.xyz / nLen;
    ConeTraceParams p = ConeTraceParams(u.coneParams[0], u.coneParams[1], u.coneParams[2],
                                        u.coneParams[3]);
    // The voxel's surface lies within half a voxel of its centre along n: the lift plane goes
    // through the top of that range, so the voxel's own cells stay out of every sample.
    float v0 = voxelSize(u.grid);
    ConeSurface surface = ConeSurface(voxelCenterWorld(u.grid, c) + 0.5 * v0 * n, n);
    float tanHalf = coneSetTanHalf(u.cones);
    vec3 gathered = vec3(0.0);
    for (uint i = 0u; i < coneSetCount(u.cones); ++i) {
        vec3 dir = coneToWorld(coneSetDirection(u.cones, i), n);
        gathered += coneSetWeight(u.cones, i) * traceSurfaceCone(surface, u.misc.x, dir, tanHalf, p).rgb;
    }
    vec3 bounce = albedo.a * albedo.rgb * (1.0 / DVS_PI) * gathered;
    imageStore(outRadiance, c, vec4(direct.rgb + bounce, direct.a));
}
