#version 460
#extension GL_GOOGLE_include_directive : require
// Filtering one level up (Crassin §4.2.3 / §8.2, notes 001 §2.3, §2.7): parent sample P[i]
// (i in {0,1,2}^3) sits at child-level vertex 2i and is the 3^3 Gaussian (1D weights 1/4 1/2 1/4)
// of the child samples 2i-1 .. 2i+1. Each parent computes the part of that sum that lies inside
// its own children (child coordinates 0..4); a child sample on the parent's boundary (coordinate 0
// or 4) is shared with the neighbouring parent and is weighted by 1/2 per such axis (inverse
// multiplicity), so the svo_transfer add/copy passes that follow complete the sums exactly.
// One thread per (node of depth d, sample). pc.args: x parent depth d, w target image
// (SVO_TARGET_RADIANCE: isotropic radiance bricks at the radiance slots, SVO_TARGET_GEOMETRY).
// The anisotropic radiance filter is svo_filter_aniso.comp.
#include "svo_common.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;

float axisWeight(int c, int i) {
    int a = c - 2 * i;
    if (a < -1 || a > 1) return 0.0;
    float w = a == 0 ? 0.5 : 0.25;
    return (c == 0 || c == 4) ? 0.5 * w : w;
}

void main() {
    uint d = pc.args.x;
    uint target = pc.args.w;
    uint t = svoThread();
    uint node = svoLevelBegin(d) + t / 27u;
    if (node >= svoLevelEnd(d)) return;
    uint word = svoTargetWord(target);
    uint brick = svoWord(node, word);
    if (brick == SVO_NONE) return;
    int k = int(t % 27u);
    ivec3 i = ivec3(k % 3, (k / 3) % 3, k / 9);
    uint child = svoWord(node, SVO_W_CHILD);
    vec4 sum = vec4(0.0);
    if (child != 0u) {
        for (int z = max(2 * i.z - 1, 0); z <= min(2 * i.z + 1, 4); ++z) {
            for (int y = max(2 * i.y - 1, 0); y <= min(2 * i.y + 1, 4); ++y) {
                for (int x = max(2 * i.x - 1, 0); x <= min(2 * i.x + 1, 4); ++x) {
                    ivec3 c = ivec3(x, y, z);
                    ivec3 o = min(c >> 1, ivec3(1));  // child 0 holds 0..2, child 1 holds 2..4
                    uint cb = svoWord(child + uint(o.x + 2 * o.y + 4 * o.z), word);
                    if (cb == SVO_NONE) continue;
                    float w = axisWeight(x, i.x) * axisWeight(y, i.y) * axisWeight(z, i.z);
                    sum += w * svoLoad(target, svoTargetOrigin(target, cb) + c - 2 * o);
                }
            }
        }
    }
    svoStore(target, svoTargetOrigin(target, brick) + i, sum);
}
