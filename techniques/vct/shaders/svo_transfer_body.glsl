// Brick-border transfer (Crassin §8.2 Fig. 9, notes 001 §2.6): per axis, pass A (pc.args.z = 0)
// adds each node's + face (9 samples) into the - face of its + neighbour; pass B (1) copies the
// sums back into the node's + face. One thread per node of depth pc.args.x, no atomics. Target
// pc.args.w (SVO_TARGET_*): 0 the irradiance accumulators (3 words per sample, by brick), 1
// radiance (the slot's brick), 2 geometry bricks, 3 the six directional radiance bricks (slot +
// 0..5, each transferred like an isotropic one; with the slab filter only along the two axes
// across the face's axis, see svo_filter_aniso.comp). Separable, so edges (4 copies) and corners
// (8) are complete after x, y, z.
#include "svo_common.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;

uint accumIndex(uint brick, ivec3 s, uint ch) {
    return (brick * 27u + uint(svoSampleIndex(s))) * 3u + ch;
}

void main() {
    uint d = pc.args.x;
    uint axis = pc.args.y;
    bool copyBack = pc.args.z != 0u;
    uint target = pc.args.w;
    uint node = svoLevelBegin(d) + svoThread();
    if (node >= svoLevelEnd(d)) return;
    uint word = svoTargetWord(target);
    uint brick = svoWord(node, word);
    if (brick == SVO_NONE) return;
    uint nb = svoWord(node, SVO_W_NBR + 2u * axis + 1u);
    if (nb == SVO_NONE) return;
    uint nbBrick = svoWord(nb, word);
    if (nbBrick == SVO_NONE) return;
    uint u = (axis + 1u) % 3u, v = (axis + 2u) % 3u;
    uint faces = target == SVO_TARGET_DIRECTIONAL ? 6u : 1u;
    for (int j = 0; j < 9; ++j) {
        ivec3 sp = ivec3(0), sm = ivec3(0);
        sp[axis] = 2;
        sp[u] = j % 3;
        sp[v] = j / 3;
        sm = sp;
        sm[axis] = 0;
        if (target == SVO_TARGET_ACCUM) {
            for (uint ch = 0u; ch < 3u; ++ch) {
                uint mine = accumIndex(brick, sp, ch), theirs = accumIndex(nbBrick, sm, ch);
                if (copyBack)
                    svoAccum[mine] = svoAccum[theirs];
                else
                    svoAccum[theirs] += svoAccum[mine];
            }
        } else {
            for (uint f = 0u; f < faces; ++f) {
                // Slab filter: a face's samples are complete along its own axis.
                if (faces == 6u && svo.radiance.w == SVO_ANISO_SLAB && (f >> 1) == axis) continue;
                ivec3 mine = svoTargetOrigin(target, brick + f) + sp;
                ivec3 theirs = svoTargetOrigin(target, nbBrick + f) + sm;
                if (copyBack)
                    svoStore(target, mine, svoLoad(target, theirs));
                else
                    svoStore(target, theirs, svoLoad(target, theirs) + svoLoad(target, mine));
            }
        }
    }
}
