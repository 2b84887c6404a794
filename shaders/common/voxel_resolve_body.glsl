// Voxel resolve (core/voxel/voxelizer.cpp): one thread per voxel divides the accumulated sums
// by the fragment count and writes the final volumes (docs/voxelization.md):
//   albedoOpacity  rgb average linear albedo, a = 1 for any covered voxel (binary coverage)
//   normal         xyz normalised average of the unit normals, w = its length before
//                  normalisation (Toksvig-style spread, notes 001 §7.2); a zero-length average
//                  gives (0, 0, 0, 0), never NaN
//   emission       rgb average emitted radiance, a = 1 for any covered voxel
// Empty voxels are 0 everywhere. VOXEL_FORMAT is the volumes' storage format qualifier.
#include "common/voxel_pc.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(set = 0, binding = 0, std430) readonly buffer VoxelAccumulators {
    uint v[];
} voxelAcc[VOXEL_ACC_WORDS];
layout(set = 0, binding = 1, VOXEL_FORMAT) uniform writeonly image3D outAlbedoOpacity;
layout(set = 0, binding = 2, VOXEL_FORMAT) uniform writeonly image3D outNormal;
layout(set = 0, binding = 3, VOXEL_FORMAT) uniform writeonly image3D outEmission;

vec3 decodeSum(uvec3 w, float fixedScale, bool signedFixed) {
    if (pc.grid.resolution.y == VOXEL_ACC_FLOAT) return uintBitsToFloat(w);
    return (signedFixed ? vec3(ivec3(w)) : vec3(w)) / fixedScale;
}
// Constant plane indices only (no descriptor-array dynamic indexing needed).
#define VOXEL_READ3(first, i) \
    uvec3(voxelAcc[first].v[i], voxelAcc[first + 1].v[i], voxelAcc[first + 2].v[i])

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (!voxelInside(pc.grid, c)) return;
    uint i = voxelLinearIndex(pc.grid, c);
    uint countWord = voxelAcc[9].v[i];
    float count = pc.grid.resolution.y == VOXEL_ACC_FLOAT ? uintBitsToFloat(countWord)
                                                          : float(countWord);
    if (!(count > 0.0)) {
        imageStore(outAlbedoOpacity, c, vec4(0.0));
        imageStore(outNormal, c, vec4(0.0));
        imageStore(outEmission, c, vec4(0.0));
        return;
    }
    vec3 albedo = decodeSum(VOXEL_READ3(0, i), VOXEL_FIXED_ALBEDO_SCALE, false) / count;
    vec3 normal = decodeSum(VOXEL_READ3(3, i), VOXEL_FIXED_NORMAL_SCALE, true) / count;
    vec3 emission = decodeSum(VOXEL_READ3(6, i), VOXEL_FIXED_EMISSION_SCALE, false) / count;
    float len = length(normal);
    vec4 n = len > 1e-6 ? vec4(normal / len, min(len, 1.0)) : vec4(0.0);
    imageStore(outAlbedoOpacity, c, vec4(albedo, 1.0));
    imageStore(outNormal, c, n);
    imageStore(outEmission, c, vec4(emission, 1.0));
}
