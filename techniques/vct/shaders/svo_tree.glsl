// Sparse voxel octree layout shared by the build / inject passes and the cone sampler
// (techniques/vct/svo.h, techniques/vct/svo.md; Crassin et al. 2011 §4.1, notes 001 §2.1).
// The includer includes vct/svo_info.glsl, declares its blocks and defines SVO_NODE(i) (a uint
// of the node pool) and SVO_INFO (an SvoInfo) before including this file.
// Node i = 12 words: child (index of the first node of its 2x2x2 tile, 0 = none), brick
// (geometry pool and flux accumulators; SVO_NONE = none), parent, neighbours -x +x -y +y -z +z,
// packed cell coordinate at its depth, depth, radiance slot (radiance pool; SVO_NONE = none).
// Node 0 is the root (depth 0); leaves are at depth D = SVO_INFO.dims.y and hold 3^3
// vertex-centred bricks with sample spacing v0: leaf cell n covers voxel centres 2n .. 2n+2 per
// axis. A node at depth d has level l = D - d (sample spacing v0 2^l). Radiance: leaves have one
// isotropic brick at their slot; non-leaf nodes one isotropic brick, or, when SVO_INFO.radiance.w
// = 1 (anisotropic), six directional bricks at slot + f, f = 0..5 = -X,+X,-Y,+Y,-Z,+Z (the values
// seen by rays travelling toward that direction, as the dense anisotropic volumes).
#ifndef GILAB_VCT_SVO_TREE_GLSL
#define GILAB_VCT_SVO_TREE_GLSL

#include "svo_info.glsl"

#define SVO_NODE_WORDS 12u
#define SVO_W_CHILD 0u
#define SVO_W_BRICK 1u
#define SVO_W_PARENT 2u
#define SVO_W_NBR 3u
#define SVO_W_COORD 9u
#define SVO_W_DEPTH 10u
#define SVO_W_RADIANCE 11u
#define SVO_NONE 0xFFFFFFFFu

uint svoWord(uint node, uint w) { return SVO_NODE(node * SVO_NODE_WORDS + w); }

uint svoPackCoord(uvec3 c) { return c.x | (c.y << 10) | (c.z << 20); }
uvec3 svoUnpackCoord(uint p) { return uvec3(p & 1023u, (p >> 10) & 1023u, (p >> 20) & 1023u); }

/** Node at `depth` whose cell is `cell`, descending from the root; SVO_NONE when a node on the
 *  way has no children (collapsed empty space). */
uint svoFindNode(uvec3 cell, uint depth) {
    uint node = 0u;
    for (uint k = 0u; k < depth; ++k) {
        uint child = svoWord(node, SVO_W_CHILD);
        if (child == 0u) return SVO_NONE;
        uvec3 o = (cell >> (depth - k - 1u)) & 1u;
        node = child + o.x + 2u * o.y + 4u * o.z;
    }
    return node;
}

/** First texel of brick b in the geometry pool (bricks are 3^3 texels). */
ivec3 svoBrickOrigin(uint b) {
    uint bx = SVO_INFO.dims.z, by = SVO_INFO.capacity.w;
    return 3 * ivec3(int(b % bx), int((b / bx) % by), int(b / (bx * by)));
}

/** First texel of radiance brick `slot` in the radiance pool. */
ivec3 svoRadianceOrigin(uint slot) {
    uint bx = SVO_INFO.radiance.y, by = SVO_INFO.radiance.z;
    return 3 * ivec3(int(slot % bx), int((slot / bx) % by), int(slot / (bx * by)));
}

// SVO_INFO.radiance.w: 0 isotropic, else the directional filter of svo_filter_aniso.comp.
#define SVO_ANISO_PAIRS 1u
#define SVO_ANISO_SLAB 2u

/** Non-leaf nodes store six directional radiance bricks. */
bool svoAnisotropic() { return SVO_INFO.radiance.w != 0u; }

#endif  // GILAB_VCT_SVO_TREE_GLSL
