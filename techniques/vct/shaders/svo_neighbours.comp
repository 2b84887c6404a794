#version 460
#extension GL_GOOGLE_include_directive : require
// Octree build, step 4: neighbour pointers (-x +x -y +y -z +z) of every node of depth d, found
// by descending from the root to the neighbouring cell (Crassin §4.1: needed by the border
// transfer, notes 001 §2.6). SVO_NONE where the neighbour was collapsed or lies outside.
#include "svo_common.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;

void main() {
    uint d = pc.args.x;
    uint node = svoLevelBegin(d) + svoThread();
    if (node >= svoLevelEnd(d)) return;
    ivec3 c = ivec3(svoUnpackCoord(svoWord(node, SVO_W_COORD)));
    int n = int(svo.depthInfo[d].y);
    for (uint j = 0u; j < 6u; ++j) {
        ivec3 o = ivec3(0);
        o[j >> 1] = (j & 1u) == 0u ? -1 : 1;
        ivec3 q = c + o;
        uint nb = SVO_NONE;
        if (all(greaterThanEqual(q, ivec3(0))) && all(lessThan(q, ivec3(n))))
            nb = svoFindNode(uvec3(q), d);
        svoNodes[node * SVO_NODE_WORDS + SVO_W_NBR + j] = nb;
    }
}
