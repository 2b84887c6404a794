// Facing weight of a voxel's outgoing radiance (Crassin §7: a voxel is shaded toward the cone
// through its averaged normal; issue 9). m = the voxel's mean normal (Toksvig: |m| = 1 for one
// plane, 0 for opposite faces or none). The voxel is read as a fraction (1 + |m|) / 2 of surface
// facing m and (1 - |m|) / 2 facing -m; a cone travelling along unit `dir` sees the side facing
// it, relative to the brighter side: 1 in front, (1 - |m|) / (1 + |m|) behind, a linear ramp
// over +-14 deg around grazing. One plane is then black from behind; no normal is isotropic.
// Radiance only: opacity is never weighted (a wall blocks from both sides).
#ifndef GILAB_VOXEL_FACING_GLSL
#define GILAB_VOXEL_FACING_GLSL

float voxelFacing(vec3 m, vec3 dir) {
    float len = length(m);
    if (!(len > 1e-4)) return 1.0;
    len = min(len, 1.0);
    float front = clamp(0.5 - 2.0 * dot(m, dir) / length(m), 0.0, 1.0);
    return mix((1.0 - len) / (1.0 + len), 1.0, front);
}

// The mean normal of the voxelizer's normal volume texel (xyz unit average, w its length).
vec3 voxelMeanNormal(vec4 nl) { return nl.xyz * clamp(nl.w, 0.0, 1.0); }

// The mean normal of a trilinear sample of that volume, next to the trilinear coverage
// `coverage` (the radiance opacity, 1 per covered voxel): empty neighbours scale both xyz and w,
// so dividing by the coverage recovers the covered voxels' mean.
vec3 voxelMeanNormalFiltered(vec4 nl, float coverage) {
    if (!(coverage > 1e-4)) return vec3(0.0);
    return (nl.xyz / coverage) * clamp(nl.w / coverage, 0.0, 1.0);
}

#endif  // GILAB_VOXEL_FACING_GLSL
