// Dense photon splat (notes 001 §2.5 step 2): one thread per photon adds its flux to the voxel
// that holds it. A photon lies on a voxelized surface, so its voxel is covered; round-off at a
// voxel face can put it in the empty neighbour, so an empty voxel is retried half a voxel toward
// and away from the light. Photons outside the grid or with no hit are dropped.
#include "vct/inject_common.glsl"

layout(local_size_x = 64) in;

bool covered(ivec3 c) {
    return voxelInside(pc.grid, c) && texelFetch(voxelAlbedoOpacity, c, 0).a > 0.0;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.counts.x) return;
    Photon p = photons[i];
    if (p.positionValid.w < 0.5) return;
    float v0 = voxelSize(pc.grid);
    ivec3 c = voxelCoordOf(pc.grid, p.positionValid.xyz);
    if (!covered(c)) {
        ivec3 toward = voxelCoordOf(pc.grid, p.positionValid.xyz + 0.5 * v0 * p.toLight.xyz);
        ivec3 away = voxelCoordOf(pc.grid, p.positionValid.xyz - 0.5 * v0 * p.toLight.xyz);
        c = covered(toward) ? toward : (covered(away) ? away : c);
    }
    if (!voxelInside(pc.grid, c)) return;
    uint index = voxelLinearIndex(pc.grid, c);
    vec3 flux = max(p.flux.rgb, vec3(0.0));
#ifdef INJECT_FIXED_POINT
    uvec3 q = uvec3(round(flux * pc.scale.x));
    if (q.r != 0u) atomicAdd(fluxPlanes[0].v[index], q.r);
    if (q.g != 0u) atomicAdd(fluxPlanes[1].v[index], q.g);
    if (q.b != 0u) atomicAdd(fluxPlanes[2].v[index], q.b);
#else
    if (flux.r != 0.0) atomicAdd(fluxPlanes[0].v[index], flux.r);
    if (flux.g != 0.0) atomicAdd(fluxPlanes[1].v[index], flux.g);
    if (flux.b != 0.0) atomicAdd(fluxPlanes[2].v[index], flux.b);
#endif
}
