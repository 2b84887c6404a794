#version 460
#extension GL_GOOGLE_include_directive : require
// Anisotropic radiance filter one level up (Crassin §9, notes 001 §2.8; techniques/vct/svo.md
// "Anisotropic"): writes the six directional bricks (slot + f, f = -X,+X,-Y,+Y,-Z,+Z) of every
// node of depth d. Children are the leaves' isotropic bricks (d + 1 = D) or the children's
// bricks of the same face.
//
// The 3^3 Gaussian of svo_filter.comp is, along any axis a, the mean of two pair averages:
// 1/4 C[2i-1] + 1/2 C[2i] + 1/4 C[2i+1] = 1/2 [ (C[2i-1] + C[2i]) / 2 + (C[2i] + C[2i+1]) / 2 ].
// Face f on axis a replaces each pair average by the dense anisotropic filter's front-to-back
// composite (core/voxel/voxel_radiance, voxel_radiance_aniso_body.glsl)
//     front + (1 - front.a) back      (premultiplied rgb and a),
// front = the child sample a ray travelling toward f meets first (+X: the smaller coordinate),
// and keeps the tent weights (with inverse multiplicity) along the two other axes:
//     P_f[i] = sum_{u,v} w(u) w(v) 1/2 sum_{pairs along a} composite(pair).
// Every pair lies inside one child (child coordinates 0..4, pairs (0,1) (1,2) | (2,3) (3,4)), so
// a parent computes the pairs of its own children and the add/copy transfer across parents
// completes boundary samples exactly, as for the isotropic filter. For small opacities P_f is
// twice the Gaussian (a parent voxel is twice as thick); a one-voxel wall through a parent's
// centre sample keeps a = 1 along its normal (on an odd child sample: 1/2 in both parents).
// Slab filter (svo.radiance.w = SVO_ANISO_SLAB, SparseVoxelOctree::DirectionalFilter::Slab): one
// front-to-back step through the footprint 2i-1 .. 2i+1 with half-depth end samples,
//     P_f[i] = sum_{u,v} w(u) w(v) [ h(front) + (1 - a) (C[2i] + (1 - a) h(back)) ],
// h = halfSlab; it spans two parents along a, so child samples -1 and 5 are read from the
// neighbour's children and the transfer skips the face's own axis (svo_transfer_body.glsl).
// Facing (Crassin §7, common/voxel_facing.glsl; as the dense first directional level,
// voxel_radiance_aniso_body.glsl): at level D - 1 each leaf child sample's colour is weighted by
// voxelFacing(its mean normal, the face's travel direction) before compositing (opacity kept),
// so a lit surface shines only toward its front in every directional brick above the leaves.
// One thread per (node of depth d, sample); pc.args.x = d.
#include "svo_common.glsl"
#include "common/voxel_facing.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;

float axisWeight(int c, int i) {
    int a = c - 2 * i;
    if (a < -1 || a > 1) return 0.0;
    float w = a == 0 ? 0.5 : 0.25;
    return (c == 0 || c == 4) ? 0.5 * w : w;
}

uint gNode;
uint gChild;
bool gLeafChildren;
const vec3 kFaceTravel[6] = vec3[6](vec3(-1, 0, 0), vec3(1, 0, 0), vec3(0, -1, 0), vec3(0, 1, 0),
                                    vec3(0, 0, -1), vec3(0, 0, 1));

// Child-level sample at parent-local coordinate c of the source of face f: c in 0..4 per axis
// inside this node's children (copies shared by two children agree after their transfer, so
// child min(c / 2, 1) is read); c = -1 or 5 along one axis (slab filter only) lies in the
// children of the neighbouring node on that side.
// Leaf children (gLeafChildren) also return the sample's mean normal m (xyz * length).
vec4 childSample(ivec3 c, uint f, out vec3 m) {
    m = vec3(0.0);
    uint child = gChild;
    for (int ax = 0; ax < 3; ++ax) {
        if (c[ax] < 0 || c[ax] > 4) {
            uint nb = svoWord(gNode, SVO_W_NBR + 2u * uint(ax) + (c[ax] > 4 ? 1u : 0u));
            if (nb == SVO_NONE) return vec4(0.0);
            child = svoWord(nb, SVO_W_CHILD);
            c[ax] += c[ax] < 0 ? 4 : -4;
        }
    }
    if (child == 0u) return vec4(0.0);
    ivec3 o = min(c >> 1, ivec3(1));
    uint node = child + uint(o.x + 2 * o.y + 4 * o.z);
    uint slot = svoWord(node, SVO_W_RADIANCE);
    if (slot == SVO_NONE) return vec4(0.0);
    uint s = gLeafChildren ? slot : slot + f;
    if (gLeafChildren) {
        uint brick = svoWord(node, SVO_W_BRICK);
        if (brick != SVO_NONE)
            m = voxelMeanNormal(imageLoad(svoNormals, svoBrickOrigin(brick) + c - 2 * o));
    }
    return max(imageLoad(svoRadiance, svoRadianceOrigin(s) + c - 2 * o), vec4(0.0));
}

vec4 nbh[27];    // child samples 2i - 1 + n (n = 0..2 per axis)
vec3 nbhM[27];   // their mean normals (leaf children only)

// Neighbourhood sample n as seen by rays of face f: leaf colours facing-weighted, opacity kept.
vec4 facedSample(ivec3 m, uint f) {
    int n = m.x + 3 * (m.y + 3 * m.z);
    vec4 v = nbh[n];
    if (gLeafChildren) v.rgb *= voxelFacing(nbhM[n], kFaceTravel[f]);
    return v;
}

vec4 composite(vec4 front, vec4 back) { return front + (1.0 - clamp(front.a, 0.0, 1.0)) * back; }

// Half the depth of a voxel (emission-absorption): a' = 1 - (1 - a)^(1/2), rgb scaled by a' / a.
vec4 halfSlab(vec4 v) {
    float a = clamp(v.a, 0.0, 1.0);
    if (!(a > 1e-6)) return 0.5 * v;
    float h = a >= 1.0 ? 1.0 : 1.0 - sqrt(1.0 - a);
    return vec4(v.rgb * (h / a), h);
}

void main() {
    uint d = pc.args.x;
    uint t = svoThread();
    uint node = svoLevelBegin(d) + t / 27u;
    if (node >= svoLevelEnd(d)) return;
    uint slot = svoWord(node, SVO_W_RADIANCE);
    if (slot == SVO_NONE) return;
    int k = int(t % 27u);
    ivec3 i = ivec3(k % 3, (k / 3) % 3, k / 9);
    gNode = node;
    gChild = svoWord(node, SVO_W_CHILD);
    gLeafChildren = d + 1u >= svo.dims.y;
    bool slab = svo.radiance.w == SVO_ANISO_SLAB;
    // Child samples 2i - 1 + n (n = 0..2 per axis); outside the node's children: zero (pairs)
    // or, along the face's axis, the neighbour's (slab).
    for (uint f = 0u; f < 6u; ++f) {
        int axis = int(f >> 1);
        if (f == 0u || !gLeafChildren || (slab && (f & 1u) == 0u)) {
            for (int n = 0; n < 27; ++n) {
                ivec3 m = ivec3(n % 3, (n / 3) % 3, n / 9);
                ivec3 c = 2 * i - 1 + m;
                bool inside = all(greaterThanEqual(c, ivec3(0))) && all(lessThanEqual(c, ivec3(4)));
                ivec3 cc = clamp(c, ivec3(0), ivec3(4));
                cc[axis] = c[axis];
                bool along = all(equal(cc, c));  // outside only along the face's axis
                vec3 normal = vec3(0.0);
                nbh[n] = (inside || (slab && along)) ? childSample(c, f, normal) : vec4(0.0);
                nbhM[n] = normal;
            }
        }
        bool towardPositive = (f & 1u) != 0u;  // +X: rays enter the smaller coordinate first
        int au = (axis + 1) % 3, av = (axis + 2) % 3;
        vec4 sum = vec4(0.0);
        for (int nu = 0; nu < 3; ++nu) {
            for (int nv = 0; nv < 3; ++nv) {
                float w = axisWeight(2 * i[au] - 1 + nu, i[au]) *
                          axisWeight(2 * i[av] - 1 + nv, i[av]);
                if (w == 0.0 || 2 * i[au] - 1 + nu < 0 || 2 * i[au] - 1 + nu > 4 ||
                    2 * i[av] - 1 + nv < 0 || 2 * i[av] - 1 + nv > 4)
                    continue;
                ivec3 m = ivec3(0);
                m[au] = nu;
                m[av] = nv;
                ivec3 m0 = m, m1 = m, m2 = m;
                m1[axis] = 1;
                m2[axis] = 2;
                vec4 lo = facedSample(m0, f);   // child sample 2i - 1
                vec4 mid = facedSample(m1, f);  // 2i
                vec4 hi = facedSample(m2, f);   // 2i + 1
                if (slab) {
                    // One integration step through the footprint 2i-1 .. 2i+1 (half slabs at the
                    // ends, shared with the neighbouring parent samples).
                    sum += w * (towardPositive ? composite(halfSlab(lo), composite(mid, halfSlab(hi)))
                                               : composite(halfSlab(hi), composite(mid, halfSlab(lo))));
                } else {
                    // Pairs (2i-1, 2i) and (2i, 2i+1); a pair outside the node's children is
                    // the neighbour's part (completed by the transfer).
                    if (2 * i[axis] - 1 >= 0)
                        sum += (0.5 * w) * (towardPositive ? composite(lo, mid) : composite(mid, lo));
                    if (2 * i[axis] + 1 <= 4)
                        sum += (0.5 * w) * (towardPositive ? composite(mid, hi) : composite(hi, mid));
                }
            }
        }
        imageStore(svoRadiance, svoRadianceOrigin(slot + f) + i, sum);
    }
}
