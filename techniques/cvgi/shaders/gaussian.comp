#version 460
#extension GL_GOOGLE_include_directive : require
// Emitter update, step 4 (§4.4): one pass of the 3D Gaussian over the same-direction faces of the
// neighbours of each camera-visible voxel. Empty neighbours, neighbours not gathered for this
// emitter state and faces that gathered nothing ("non-lit") get weight 0, then the weights are
// renormalised (no shadow leaks). Run twice: faceIrradiance -> faceTemp -> faceFiltered.
// gaussian_visibility (ours, u.packing.w): a neighbour also gets weight 0 when the straight path
// between the two faces' front cells crosses an occupied voxel, or either front cell is occupied
// (a buried face), so a lit face does not spread through a wall (techniques/cvgi/README.md, "The Gaussian filter").
#include "cvgi_common.glsl"

layout(local_size_x = 64) in;

// Buffers: 0 faceIrradiance, 1 faceTemp, 2 faceFiltered (the host ping-pongs them).
layout(push_constant, std430) uniform Push {
    uint src;
    uint dst;
    uint copy;    // 1: dst = src (no filtering)
    uint stride;  // threads per dispatch row
} pc;

vec4 source(uint face) {
    return pc.src == 0u ? faceIrradiance[face] : (pc.src == 1u ? faceTemp[face] : faceFiltered[face]);
}
void store(uint face, vec4 e) {
    if (pc.dst == 1u) faceTemp[face] = e;
    else faceFiltered[face] = e;
}

// True when cells a and b are empty and no occupied voxel lies between them (sampled at the cells
// the segment passes through, one per step of its longest axis). An occupied end is a buried face:
// it cannot tell which side of a wall it serves (a ceiling voxel in a one-voxel wall's column
// would take the lit room's ceiling through the wall), so it neither gives nor takes.
bool pathOpen(ivec3 a, ivec3 b) {
    if (cvgiIndexAt(a) != CVGI_EMPTY || cvgiIndexAt(b) != CVGI_EMPTY) return false;
    ivec3 d = b - a;
    int steps = max(abs(d.x), max(abs(d.y), abs(d.z)));
    for (int k = 1; k < steps; ++k) {
        ivec3 p = a + ivec3(round(vec3(d) * (float(k) / float(steps))));
        if (p != a && p != b && cvgiIndexAt(p) != CVGI_EMPTY) return false;
    }
    return true;
}

void main() {
    uint t = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * pc.stride;
    if (t >= u.counts.x * 6u) return;
    uint i = t / 6u, f = t % 6u;
    if ((voxelState[i] & CVGI_VISIBLE) == 0u) return;
    if (pc.copy != 0u) {
        store(t, source(t));
        return;
    }
    int radius = int(u.options.x);
    float inv2s2 = 0.5 / (u.biases.w * u.biases.w);
    ivec3 c = cvgiCoord(i);
    ivec3 front = c + cvgiAxisDir(f);
    bool visibility = u.packing.w != 0u;
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (int z = -radius; z <= radius; ++z)
        for (int y = -radius; y <= radius; ++y)
            for (int x = -radius; x <= radius; ++x) {
                uint j = cvgiIndexAt(c + ivec3(x, y, z));
                if (j == CVGI_EMPTY || (voxelState[j] & CVGI_PROCESSED) == 0u) continue;
                vec4 e = source(6u * j + f);
                if (e.w <= 0.0 || max(e.r, max(e.g, e.b)) <= 0.0) continue;  // non-lit face
                bool self = x == 0 && y == 0 && z == 0;
                if (visibility && !self && !pathOpen(front, front + ivec3(x, y, z))) continue;
                float w = exp(-float(x * x + y * y + z * z) * inv2s2);
                sum += w * e.rgb;
                weight += w;
            }
    store(t, vec4(weight > 0.0 ? sum / weight : vec3(0.0), 1.0));
}
