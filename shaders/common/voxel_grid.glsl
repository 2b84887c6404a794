// The voxel grid shared by every voxel technique (core/voxel/voxel_grid.h, docs/voxelization.md).
// An axis-aligned cube: `origin` is its minimum corner, `voxelSize` the edge of one voxel and
// `resolution` the voxel count per axis. Grid space: g = (p - origin) / voxelSize, so voxel
// ivec3(floor(g)) spans [i, i+1)^3 and its centre is i + 0.5 (notes 003 §7.6: centres, not
// corners). Texture space (for textureLod on the volumes): uvw = g / resolution.
// Mirrored by gilab::GpuVoxelGrid (32 bytes).
#ifndef GILAB_VOXEL_GRID_GLSL
#define GILAB_VOXEL_GRID_GLSL

struct VoxelGridInfo {
    vec4 originVoxelSize;  // xyz minimum corner (world), w voxel size (world units)
    uvec4 resolution;      // x voxels per axis, y accumulator mode (VOXEL_ACC_*), zw unused
};

// Accumulators (core/voxel/voxelizer.h): VOXEL_ACC_WORDS planes of one 32-bit word per voxel,
// [albedo.rgb, normal.xyz, emission.rgb, fragment count], each indexed by voxelLinearIndex.
#define VOXEL_ACC_WORDS 10
#define VOXEL_ACC_FLOAT 0u
#define VOXEL_ACC_FIXED 1u
// Fixed-point scales of the uint fallback (no VK_EXT_shader_atomic_float). Overflow bounds per
// voxel: 65535 fragments (albedo, normal), emission sum < 4.19e6 per channel.
#define VOXEL_FIXED_ALBEDO_SCALE 65535.0
#define VOXEL_FIXED_NORMAL_SCALE 32767.0
#define VOXEL_FIXED_EMISSION_SCALE 1024.0

uint voxelResolution(VoxelGridInfo g) { return g.resolution.x; }
float voxelSize(VoxelGridInfo g) { return g.originVoxelSize.w; }
vec3 voxelWorldToGrid(VoxelGridInfo g, vec3 p) {
    return (p - g.originVoxelSize.xyz) / g.originVoxelSize.w;
}
vec3 voxelGridToWorld(VoxelGridInfo g, vec3 q) {
    return g.originVoxelSize.xyz + q * g.originVoxelSize.w;
}
vec3 voxelWorldToUvw(VoxelGridInfo g, vec3 p) {
    return voxelWorldToGrid(g, p) / float(g.resolution.x);
}
ivec3 voxelCoordOf(VoxelGridInfo g, vec3 p) { return ivec3(floor(voxelWorldToGrid(g, p))); }
vec3 voxelCenterWorld(VoxelGridInfo g, ivec3 c) { return voxelGridToWorld(g, vec3(c) + 0.5); }
bool voxelInside(VoxelGridInfo g, ivec3 c) {
    return all(greaterThanEqual(c, ivec3(0))) && all(lessThan(c, ivec3(g.resolution.x)));
}
uint voxelLinearIndex(VoxelGridInfo g, ivec3 c) {
    uint n = g.resolution.x;
    return uint(c.x) + n * (uint(c.y) + n * uint(c.z));
}

#endif  // GILAB_VOXEL_GRID_GLSL
