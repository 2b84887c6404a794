// Virtual point lights (VPLs) and their clusters, shared by the VPL techniques (core/vpl/vpl.h
// mirrors the structs, std430), and the sampling and paraboloid-map mathematics they use
// (core/vpl/vpl_math.h is the C++ mirror the CPU tests check).
#ifndef GILAB_VPL_GLSL
#define GILAB_VPL_GLSL

// A VPL is a cosine-emitting oriented point: intensity I(w) = flux * max(0, n.w) / pi.
struct Vpl {
    vec4 position;  // xyz world position, w 1 = valid (0: no surface behind the sample)
    vec4 normal;    // xyz unit normal (emitting side), w visibility map layer (-1: unshadowed)
    vec4 flux;      // rgb flux [W], w bounce (1, 2)
};

// A cluster of VPLs (K-means, Dong et al. 2009; Aranha et al. §III-B) with its paraboloid map.
struct VplCluster {
    vec4 position;  // xyz centroid (the map's eye, offset along the normal), w 1 = active
    vec4 normal;    // xyz unit mean normal (the map's axis), w member count
    vec4 flux;      // rgb summed member flux [W], w unused
    vec4 mean;      // xyz plain member mean (K-means state, before the offset), w unused
};

const float VPL_PI = 3.14159265358979323846;

bool vplFinite(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

// Eq. 1 of Aranha et al.: the 2D Hammersley point k of n, (k / n, radical inverse of k).
vec2 vplHammersley(uint k, uint n) {
    return vec2(float(k) / float(n), float(bitfieldReverse(k)) * 2.3283064365386963e-10);
}

// The same point under a Cranley-Patterson rotation (a toroidal shift by `shift` in [0,1)^2, from
// a technique's `seed`: core/vpl/vpl_math.h cranleyPattersonShift); shift 0 is the point itself.
vec2 vplHammersleyShifted(uint k, uint n, vec2 shift) {
    return fract(vplHammersley(k, n) + shift);
}

// Shirley-Chiu concentric map of [0,1)^2 onto the unit disk: uniform in area, stratification kept.
vec2 vplConcentricDisk(vec2 u) {
    vec2 o = 2.0 * u - 1.0;
    if (o.x == 0.0 && o.y == 0.0) return vec2(0.0);
    float r, phi;
    if (abs(o.x) > abs(o.y)) {
        r = o.x;
        phi = 0.25 * VPL_PI * (o.y / o.x);
    } else {
        r = o.y;
        phi = 0.5 * VPL_PI - 0.25 * VPL_PI * (o.x / o.y);
    }
    return r * vec2(cos(phi), sin(phi));
}

// Orthonormal frame around unit n (Duff et al. 2017, branchless): rows t, b, n, so that
// frame * v gives v in the local frame with +z = n.
mat3 vplFrame(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    vec3 t = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    vec3 bt = vec3(b, s + n.y * n.y * a, -n.y);
    return transpose(mat3(t, bt, n));
}

// Hemispherical paraboloid map (Heidrich & Seidel 1998; Aranha et al. Eq. 3-5): a unit local
// direction d with d.z >= 0 maps to the disk point d.xy / (1 + d.z); the inverse is
// d = (2x, 2y, 1 - r^2) / (1 + r^2). Solid angle per unit disk area: 4 / (1 + r^2)^2.
vec2 vplParaboloidProject(vec3 d) { return d.xy / (1.0 + d.z); }
vec3 vplParaboloidDirection(vec2 p) {
    float r2 = dot(p, p);
    return vec3(2.0 * p, 1.0 - r2) / (1.0 + r2);
}
// Disk point <-> texture coordinate in [0,1]^2 (y down like every image here).
vec2 vplParaboloidUv(vec2 p) { return 0.5 * p + 0.5; }
vec2 vplParaboloidPoint(vec2 uv) { return 2.0 * uv - 1.0; }

// Flux weight of a second-bounce VPL drawn uniformly on a cluster's disk (core/vpl/vpl_math.h):
// the cluster's cosine emission over the disk density, 4 (1 - r^2) / (1 + r^2)^3; mean 1.
float vplDiskSampleWeight(vec2 p) {
    float r2 = dot(p, p);
    float q = 1.0 + r2;
    return 4.0 * max(1.0 - r2, 0.0) / (q * q * q);
}

// Interleaved shading over a Hammersley-ordered set of n VPLs in stride = I^2 subsets
// (core/vpl/vpl_math.h mirrors it; docs/vpl.md "Gathering"). Point k's x is k / n (the high
// bits of k) and its y the radical inverse (the low bits), so subset k mod stride, the usual
// choice, is one thin strip of y. With stride = 2^t, point k joins subset
//   fold(k) xor rotation,  fold(k) = the xor of k's t-bit chunks,
// and any t consecutive bits of k then decide the subset one-to-one: every elementary box of
// the set holding stride points, of any aspect ratio, has one point of each subset. Other
// strides: blocks of L consecutive points go round-robin, subset (k / L + rotation) mod stride,
// L the largest power of two with L^2 stride <= n (L strata of y, n / (L stride) of x).
// A set too small for blocks of 4 or more (L < 4: fewer than 16 stride points; ssvp's
// second-bounce disk sets of N2 / C = 32 at I = 4 gave L = 1, i.e. `modulo`'s strips) is split by
// fold when the stride is a power of two (measured better than blocks there, issue 43), else row
// by row: point k = h stride + j of row h joins subset (j + c h + rotation) mod stride, c = 1 for
// an even stride and 2 for an odd one, so that a subset's points in successive rows are
// stride - c apart, an odd step: their low bits, y's high bits, differ, and each row is one x
// stratum.
uint vplInterleaveBlock(uint n, uint stride) {
    uint block = 1u;
    while (4u * block * block * stride <= n) block *= 2u;
    return block;
}
uint vplRowShift(uint stride) { return (stride & 1u) == 0u ? 1u : 2u; }
bool vplPowerOfTwo(uint v) { return v > 0u && (v & (v - 1u)) == 0u; }
uint vplFold(uint k, uint stride) {
    if (stride <= 1u) return 0u;
    uint bits = uint(findLSB(stride)), s = 0u;
    for (; k != 0u; k >>= bits) s ^= k & (stride - 1u);
    return s;
}
// mode (core/vpl/vpl_shading.h InterleaveSubsets): 0 fold (power-of-two strides, else blocks),
// 1 blocks (small sets: fold or shifted rows), 2 modulo (k + rotation) mod stride.
// Blocks of fewer than 4 points per run: the small-set rule above.
bool vplSmallSet(uint n, uint stride) { return vplInterleaveBlock(n, stride) < 4u; }
uint vplInterleaveSubset(uint k, uint n, uint stride, uint rotation, uint mode) {
    if (mode == 2u) return (k + rotation) % stride;
    bool small = vplSmallSet(n, stride);
    if ((mode == 0u || small) && vplPowerOfTwo(stride))
        return vplFold(k, stride) ^ (rotation & (stride - 1u));
    if (small) return (k % stride + (vplRowShift(stride) * (k / stride)) % stride + rotation) % stride;
    return (k / vplInterleaveBlock(n, stride) + rotation) % stride;
}

#endif  // GILAB_VPL_GLSL
