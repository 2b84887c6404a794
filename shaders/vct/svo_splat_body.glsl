// Photon splat into the octree's leaves (Crassin §8.2, notes 001 §2.5): one thread per photon.
// Like the dense splat (vct/splat_dense_body.glsl), the photon's flux goes to the voxel s that
// holds it, i.e. the lattice sample s (its centre); the leaf cell floor(s / 2) is found by
// descending from the root and the flux is added atomically to that brick's copy of the sample
// (local index s - 2 floor(s / 2) in {0, 1}). svo_transfer then adds the duplicated copies.
// An uncovered voxel (round-off at a face) is retried half a voxel toward / away from the light.
#include "vct/svo_common.glsl"

layout(set = 2, binding = 0, std430) readonly buffer Photons {
    Photon photons[];
};
layout(local_size_x = SVO_GROUP_SIZE) in;

// Leaf node and brick holding sample s, or SVO_NONE; brick sample covered (geometry a > 0).
uint leafBrickOf(ivec3 s, out ivec3 local, out bool covered) {
    covered = false;
    local = ivec3(0);
    if (any(lessThan(s, ivec3(0))) || any(greaterThanEqual(s, ivec3(svo.dims.x)))) return SVO_NONE;
    uvec3 cell = uvec3(s >> 1);
    uint node = svoFindNode(cell, svo.dims.y);
    if (node == SVO_NONE) return SVO_NONE;
    uint brick = svoWord(node, SVO_W_BRICK);
    if (brick == SVO_NONE) return SVO_NONE;
    local = s - 2 * ivec3(cell);
    covered = imageLoad(svoGeometry, svoBrickOrigin(brick) + local).a > 0.0;
    return brick;
}

void main() {
    uint i = svoThread();
    if (i >= pc.args.x) return;
    Photon p = photons[i];
    if (p.positionValid.w < 0.5) return;
    float v0 = svo.originVoxelSize.w;
    vec3 origin = svo.originVoxelSize.xyz;
    ivec3 local;
    bool covered;
    ivec3 s = ivec3(floor((p.positionValid.xyz - origin) / v0));
    uint brick = leafBrickOf(s, local, covered);
    if (!covered) {
        for (int k = 0; k < 2 && !covered; ++k) {
            vec3 q = p.positionValid.xyz + (k == 0 ? 0.5 : -0.5) * v0 * p.toLight.xyz;
            ivec3 s2 = ivec3(floor((q - origin) / v0));
            ivec3 local2;
            uint b2 = leafBrickOf(s2, local2, covered);
            if (covered) {
                brick = b2;
                local = local2;
            }
        }
    }
    if (brick == SVO_NONE) return;
    vec3 flux = max(p.flux.rgb, vec3(0.0));
    uint base = (brick * 27u + uint(svoSampleIndex(local))) * 3u;
#ifdef SVO_FLOAT_ACCUM
    for (uint ch = 0u; ch < 3u; ++ch)
        if (flux[ch] != 0.0) atomicAdd(svoAccum[base + ch], flux[ch]);
#else
    uvec3 q = uvec3(round(flux * pc.scale.x));
    for (uint ch = 0u; ch < 3u; ++ch)
        if (q[ch] != 0u) atomicAdd(svoAccum[base + ch], q[ch]);
#endif
}
