// One voxel fragment of the per-voxel fragment lists (core/voxel/voxel_fragments.h, mirrored by
// gilab::GpuVoxelFragment, 32 bytes): world position, list link, octahedral normal and albedo.
#ifndef GILAB_VOXEL_FRAGMENTS_GLSL
#define GILAB_VOXEL_FRAGMENTS_GLSL

#define VOXEL_LIST_END 0xFFFFFFFFu

struct VoxelFragment {
    vec3 position;  // world
    uint next;      // next fragment of the same voxel, VOXEL_LIST_END at the tail
    uint normalOct; // packSnorm2x16 of the octahedral encoding
    uint albedoLo;  // packHalf2x16(albedo.rg)
    uint albedoHi;  // packHalf2x16(albedo.b, 0)
    uint pad;
};

vec2 voxelOctWrap(vec2 v) { return (1.0 - abs(v.yx)) * mix(vec2(-1.0), vec2(1.0), greaterThanEqual(v, vec2(0.0))); }

VoxelFragment voxelPackFragment(vec3 position, vec3 normal, vec3 albedo, uint next) {
    vec3 n = normal / max(abs(normal.x) + abs(normal.y) + abs(normal.z), 1e-20);
    vec2 oct = n.z >= 0.0 ? n.xy : voxelOctWrap(n.xy);
    VoxelFragment f;
    f.position = position;
    f.next = next;
    f.normalOct = packSnorm2x16(oct);
    f.albedoLo = packHalf2x16(albedo.rg);
    f.albedoHi = packHalf2x16(vec2(albedo.b, 0.0));
    f.pad = 0u;
    return f;
}

#endif  // GILAB_VOXEL_FRAGMENTS_GLSL
