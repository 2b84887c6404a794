// Facing weight of a voxel's outgoing radiance (Crassin §7: a voxel is shaded toward the cone
// through its averaged normal; issue 9). nl = the voxelizer's normal volume texel: xyz the unit
// average normal, w its length |N| before normalisation (1 = one plane, 0 = none or opposite
// faces). A cone travelling along unit `dir` sees a plane's radiance when the plane faces it
// (n . dir < 0): front = 1 facing, 0 turned away, a linear ramp over +-14 deg around grazing.
// Spread normals (|N| < 1) fall back toward isotropic: weight = mix(1, front, |N|). Radiance
// only; opacity is never weighted (a wall blocks from both sides).
#ifndef GILAB_VOXEL_FACING_GLSL
#define GILAB_VOXEL_FACING_GLSL

float voxelFacing(vec4 nl, vec3 dir) {
    float spread = clamp(nl.w, 0.0, 1.0);
    float front = clamp(0.5 - 2.0 * dot(nl.xyz, dir), 0.0, 1.0);
    return mix(1.0, front, spread);
}

#endif  // GILAB_VOXEL_FACING_GLSL
