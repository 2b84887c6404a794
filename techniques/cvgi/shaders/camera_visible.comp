#version 460
#extension GL_GOOGLE_include_directive : require
// Emitter update, step 3a (§4.4, Fig. 5 left): a voxel is camera-visible when any of 12 points at
// 2 s from its centre (edge-centre directions) is seen by the small camera distance map. Visible
// voxels not yet PROCESSED for this emitter state go to the gather list (the paper's cache: a
// camera-only move gathers only newly visible voxels; an emitter change clears PROCESSED).
#include "cvgi_common.glsl"

layout(local_size_x = 64) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u.counts.x) return;
    ivec3 c = cvgiCoord(i);
    float s = voxelSize(u.grid);
    vec3 centre = voxelCenterWorld(u.grid, c);
    bool seen = false;
    for (uint k = 6u; k < 18u && !seen; ++k) {
        vec3 p = centre + 2.0 * s * cvgiTestDirection(k);
        seen = cvgiSeen(cameraMap, u.cameraViewProj, vec4(u.cameraEye.xyz, 0.0), vec3(0.0), p,
                        u.biases.y * s);
    }
    uint state = voxelState[i] & ~CVGI_VISIBLE;
    if (seen) {
        state |= CVGI_VISIBLE;
        atomicAdd(counters[CVGI_COUNT_VISIBLE], 1u);
        if ((state & CVGI_PROCESSED) == 0u) {
            state |= CVGI_PROCESSED;
            gatherList[atomicAdd(counters[CVGI_COUNT_GATHER], 1u)] = i;
        }
    }
    voxelState[i] = state;
}
