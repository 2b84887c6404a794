// Shared declarations of the cvgi passes (techniques/cvgi/cvgi_gpu.cpp; Cosin Ayerbe & Patow 2022,
// techniques/cvgi/README.md). Grid units: voxel i spans [i, i+1); s = voxel size (world).
// Face / axis order: -x, +x, -y, +y, -z, +z.
#ifndef GILAB_CVGI_COMMON_GLSL
#define GILAB_CVGI_COMMON_GLSL
#extension GL_EXT_scalar_block_layout : require

#include "common/voxel_grid.glsl"
#include "common/lights.glsl"

#define CVGI_EMPTY 0xFFFFFFFFu
// voxelState bits
#define CVGI_VISIBLE 1u    // seen by the camera in the latest camera test
#define CVGI_PROCESSED 2u  // faces gathered for the current emitter state (the paper's cache)
// counters
#define CVGI_COUNT_GATHER 0
#define CVGI_COUNT_VISIBLE 1
#define CVGI_COUNT_LIT 2
#define CVGI_COUNT_UNRESOLVED 3

struct CvgiVoxel {
    vec4 albedoAxis;     // rgb mean fragment reflectance, w float(heuristic axis 0..5)
    vec4 normalCluster;  // xyz mean fragment normal (0 if they cancel), w uintBitsToFloat(cluster)
};
struct CvgiCluster {
    vec4 normal;     // xyz unit mean normal
    ivec4 aabbMin;   // xyz inclusive voxel coords, w first entry in clusterVoxels
    ivec4 aabbMax;   // xyz inclusive, w voxel count
};
struct CvgiClusterLight {
    vec4 radiosity;  // rgb sum over lit voxels of B = albedo * E (W/m^2), w lit voxel count
    vec4 litCentroid;   // xyz mean lit-voxel centre (grid units)
};

layout(set = 0, binding = 0, std140) uniform CvgiUniforms {
    VoxelGridInfo grid;
    uvec4 counts;    // x voxels V, y clusters C, z resolution N, w frame width
    vec4 biases;     // x lit bias, y camera bias, z near-cluster threshold, w Gaussian sigma (voxels)
    uvec4 options;   // x Gaussian radius, y neighbour test, z interpolation, w frame height
    mat4 cameraViewProj;
    vec4 cameraEye;  // xyz
    uvec4 packing;   // x 1: faceClusters holds 16-bit ids, two per word; y 1: ray-weighted
                     // gather (faceWeights); z rays per face; w 1: the Gaussian skips
                     // neighbours behind occupied voxels
} u;

layout(set = 0, binding = 1, std430) readonly buffer VoxelIndex { uint voxelIndex[]; };
layout(set = 0, binding = 2, std430) readonly buffer HashedPosition { uint hashedPosition[]; };
layout(set = 0, binding = 3, std430) readonly buffer Voxels { CvgiVoxel voxels[]; };
layout(set = 0, binding = 4, std430) readonly buffer Clusters { CvgiCluster clusters[]; };
layout(set = 0, binding = 5, std430) readonly buffer ClusterVoxels { uint clusterVoxels[]; };
layout(set = 0, binding = 6, std430) readonly buffer FaceOffset { uint faceOffset[]; };
layout(set = 0, binding = 7, std430) readonly buffer FaceClusters { uint faceClusters[]; };
layout(set = 0, binding = 8, std430) buffer VoxelLight { vec4 voxelLight[]; };  // rgb B, w lit
layout(set = 0, binding = 9, std430) buffer ClusterLight { CvgiClusterLight clusterLight[]; };
layout(set = 0, binding = 10, std430) buffer VoxelState { uint voxelState[]; };
layout(set = 0, binding = 11, std430) buffer FaceIrradiance { vec4 faceIrradiance[]; };
layout(set = 0, binding = 12, std430) buffer FaceTemp { vec4 faceTemp[]; };
layout(set = 0, binding = 13, std430) buffer FaceFiltered { vec4 faceFiltered[]; };
layout(set = 0, binding = 14, std430) buffer Counters { uint counters[]; };
layout(set = 0, binding = 15, std430) buffer GatherList { uint gatherList[]; };
layout(set = 0, binding = 16, scalar) readonly buffer PassLights { PassLight passLights[]; };
layout(set = 0, binding = 17) uniform sampler2D emitterMap;
layout(set = 0, binding = 18) uniform sampler2D cameraMap;
// Per visibility entry: the cosine sum of the face's rays that met the cluster's front
// (ray-weighted gather only; a placeholder otherwise).
layout(set = 0, binding = 19, std430) readonly buffer FaceWeights { float faceWeights[]; };

ivec3 cvgiAxisDir(uint face) {
    ivec3 d = ivec3(0);
    d[face >> 1] = (face & 1u) != 0u ? 1 : -1;
    return d;
}

ivec3 cvgiCoord(uint i) {
    uint h = hashedPosition[i], n = u.counts.z;
    return ivec3(h % n, (h / n) % n, h / (n * n));
}

uint cvgiIndexAt(ivec3 c) {
    if (!voxelInside(u.grid, c)) return CVGI_EMPTY;
    return voxelIndex[voxelLinearIndex(u.grid, c)];
}

uint cvgiFaceCluster(uint k) {
    if (u.packing.x == 0u) return faceClusters[k];
    return (faceClusters[k >> 1] >> (16u * (k & 1u))) & 0xFFFFu;
}

uint cvgiAxis(uint i) { return uint(voxels[i].albedoAxis.w + 0.5); }
uint cvgiCluster(uint i) { return floatBitsToUint(voxels[i].normalCluster.w); }

// Whether world point p is seen by a distance-map view (shadow.frag's distances).
bool cvgiSeen(sampler2D map, mat4 viewProj, vec4 origin, vec3 direction, vec3 p, float bias) {
    vec4 clip = viewProj * vec4(p, 1.0);
    if (clip.w <= 0.0) return false;
    vec2 ndc = clip.xy / clip.w;
    if (any(greaterThan(abs(ndc), vec2(1.0)))) return false;
    float stored = textureLod(map, ndc * 0.5 + 0.5, 0.0).r;
    float d = origin.w > 0.5 ? dot(p - origin.xyz, direction) : length(p - origin.xyz);
    return d <= stored + bias;
}

// The 18 emitter test directions (6 face centres, 12 edge centres; §4.4, Fig. 10) and the 12
// camera test directions (the edge centres), unit length.
vec3 cvgiTestDirection(uint k) {
    if (k < 6u) return vec3(cvgiAxisDir(k));
    k -= 6u;
    uint pair = k / 4u;  // 0: xy, 1: xz, 2: yz
    vec2 s = vec2((k & 1u) != 0u ? 1.0 : -1.0, (k & 2u) != 0u ? 1.0 : -1.0) * 0.70710678;
    return pair == 0u ? vec3(s, 0.0) : (pair == 1u ? vec3(s.x, 0.0, s.y) : vec3(0.0, s));
}

// Form factor from a face (receiver at x with normal n) to a Lambertian source of area A at y
// with normal m, in grid units: the point-to-coaxial-disk value A / (pi r^2 + A) with the two
// cosines (techniques/cvgi/README.md "Form factor"; C++ mirror techniques/cvgi/cvgi_form_factor.h).
float cvgiDiskFormFactor(vec3 x, vec3 n, vec3 y, vec3 m, float area) {
    vec3 d = y - x;
    float r2 = dot(d, d);
    if (r2 < 1e-12) return 0.0;
    vec3 w = d * inversesqrt(r2);
    float cosR = clamp(dot(n, w), 0.0, 1.0), cosS = clamp(-dot(m, w), 0.0, 1.0);
    return cosR * cosS * area / (3.14159265358979 * r2 + area);
}

#endif  // GILAB_CVGI_COMMON_GLSL
