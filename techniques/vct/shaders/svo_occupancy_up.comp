#version 460
#extension GL_GOOGLE_include_directive : require
// Octree build, step 2: cell m at depth d is occupied when a cell 2m-1 .. 2m+2 (per axis) at
// depth d+1 is: the 3^3 Gaussian of its brick reads child-level samples 4m-1 .. 4m+5, which lie in
// those cells (a conservative superset; it keeps "empty parent => empty children").
#include "svo_common.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;

void main() {
    uint d = pc.args.x;
    uint n = svo.depthInfo[d].y;
    uint idx = svoThread();
    if (idx >= n * n * n) return;
    ivec3 m = ivec3(idx % n, (idx / n) % n, idx / (n * n));
    int nc = int(svo.depthInfo[d + 1u].y);
    bool occupied = false;
    for (int k = 0; k < 64 && !occupied; ++k) {
        ivec3 c = 2 * m - 1 + ivec3(k % 4, (k / 4) % 4, k / 16);
        if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(nc)))) continue;
        occupied = svoOccupied(d + 1u, uvec3(c));
    }
    if (occupied) atomicOr(svoOccupancy[svo.depthInfo[d].x + (idx >> 5)], 1u << (idx & 31u));
}
