#version 460
#extension GL_GOOGLE_include_directive : require
// Octree build, step 3, one pass per depth d top-down ("flag, allocate, initialise", Crassin &
// Green 2012; notes 001 §2.2 [C]): every node of depth d that is occupied gets a brick; if one of
// its 8 child cells is occupied it gets a 2x2x2 tile of children from the global atomic counter,
// initialised with their parent, cell and depth (neighbours are linked by svo_neighbours.comp).
// Radiance slots come from a second counter: 1 brick per node, 6 per non-leaf node when the
// octree is anisotropic.
#include "svo_common.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;

void main() {
    uint d = pc.args.x;
    uint node = svoLevelBegin(d) + svoThread();
    if (node >= svoLevelEnd(d)) return;
    uvec3 c = svoUnpackCoord(svoWord(node, SVO_W_COORD));
    if (!svoOccupied(d, c)) return;
    uint brick = atomicAdd(svoCounters[1], 1u);
    if (brick < svo.capacity.y) {
        svoNodes[node * SVO_NODE_WORDS + SVO_W_BRICK] = brick;
    } else {
        atomicOr(svoCounters[2], 2u);  // brick pool overflow
        return;
    }
    uint slots = (svoAnisotropic() && d < svo.dims.y) ? 6u : 1u;
    uint slot = atomicAdd(svoCounters[3], slots);
    if (slot + slots <= svo.radiance.x) {
        svoNodes[node * SVO_NODE_WORDS + SVO_W_RADIANCE] = slot;
    } else {
        atomicOr(svoCounters[2], 4u);  // radiance pool overflow
        return;
    }
    if (d >= svo.dims.y) return;
    bool anyChild = false;
    for (uint k = 0u; k < 8u; ++k)
        anyChild = anyChild || svoOccupied(d + 1u, 2u * c + uvec3(k & 1u, (k >> 1) & 1u, k >> 2));
    if (!anyChild) return;
    uint first = atomicAdd(svoCounters[0], 8u);
    if (first + 8u > svo.capacity.x) {
        atomicOr(svoCounters[2], 1u);  // node pool overflow
        return;
    }
    for (uint k = 0u; k < 8u; ++k) {
        uint child = first + k;
        uint base = child * SVO_NODE_WORDS;
        svoNodes[base + SVO_W_CHILD] = 0u;
        svoNodes[base + SVO_W_BRICK] = SVO_NONE;
        svoNodes[base + SVO_W_PARENT] = node;
        for (uint j = 0u; j < 6u; ++j) svoNodes[base + SVO_W_NBR + j] = SVO_NONE;
        svoNodes[base + SVO_W_COORD] =
            svoPackCoord(2u * c + uvec3(k & 1u, (k >> 1) & 1u, k >> 2));
        svoNodes[base + SVO_W_DEPTH] = d + 1u;
        svoNodes[base + SVO_W_RADIANCE] = SVO_NONE;
    }
    svoNodes[node * SVO_NODE_WORDS + SVO_W_CHILD] = first;
}
