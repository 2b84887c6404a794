// Storage-independent cone march (docs/voxel_cone_tracing.md; Crassin §5, notes 001 §2.9,
// notes 003 §2.8). Before including, define
//     vec4 voxelConeSample(vec3 worldPos, float lod, vec3 dir);
// returning premultiplied radiance (rgb) and opacity (a) at level `lod` (0 = finest voxel size v0,
// fractional = linear between levels) for a cone travelling along unit `dir`. Optionally also
//     #define VOXEL_CONE_HAS_COARSE_SAMPLE
//     vec4 voxelConeSampleCoarse(vec3 worldPos, float lod, vec3 dir);   (lod >= 1 only)
// a cheaper sampler for the samples at level >= 1.
//
// Level mapping (Crassin §5: "the level corresponding to the cone radius"): the sampled voxel
// size equals the cone radius r(t) = t tan(theta/2), L = log2(r / v0) + bias, clamped to >= 0.
// Lift (docs/voxel_cone_tracing.md "Self-gather"): a cone leaving a surface (point x, normal n)
// keeps each sample at least h(L) = lift v0 2^ceil(L) above the tangent plane (lifting it along
// n), so the coarse cell holding the surface never enters the sample's quadrilinear footprint.
#ifndef GILAB_VOXEL_CONE_GLSL
#define GILAB_VOXEL_CONE_GLSL

// Safety cap on the samples of one cone (a 512^3 grid traversed at step 0.1 needs far fewer
// because the step grows with the diameter).
#ifndef VOXEL_CONE_MAX_STEPS
#define VOXEL_CONE_MAX_STEPS 1024
#endif

#ifndef VOXEL_CONE_HAS_COARSE_SAMPLE
vec4 voxelConeSampleCoarse(vec3 worldPos, float lod, vec3 dir) {
    return voxelConeSample(worldPos, lod, dir);
}
#endif

struct ConeTraceParams {
    vec4 gridMinV0;    // xyz grid minimum corner, w = v0 (finest voxel size)
    vec4 gridMaxStep;  // xyz grid maximum corner, w = step factor (d' = step * diameter, E10)
    vec4 distances;    // x max distance (world), y start offset t0 (world), z opacity cutoff,
                       // w AO lambda (1/world units)
    vec4 misc;         // x lod bias (added to the radius level), y lift factor (0 = no lift),
                       // z lift rule (0 = cell: 2^ceil(L), 1 = blend), w reserved
};

// Cone diameter at distance t (notes 003 E6), never below the finest voxel size v0.
float coneDiameter(float t, float tanHalf, float v0) {
    return max(2.0 * max(t, 0.0) * max(tanHalf, 0.0), v0);
}

// The sampled level at distance t: the level whose voxel size is the cone radius (Crassin §5),
// L = log2(radius / v0) + bias, clamped to >= 0 (0 = finest). v0 > 0.
float coneLevel(float t, float tanHalf, ConeTraceParams p) {
    float v0 = p.gridMinV0.w;
    return max(log2(0.5 * coneDiameter(t, tanHalf, v0) / v0) + p.misc.x, 0.0);
}

// Deterministic tangent frame around n (unit; a zero n falls back to +z).
vec3 coneToWorld(vec3 tangentDir, vec3 n) {
    float len = length(n);
    vec3 nz = len > 1e-8 ? n / len : vec3(0.0, 0.0, 1.0);
    vec3 guide = abs(nz.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 tx = normalize(cross(guide, nz));
    vec3 ty = cross(nz, tx);
    return tangentDir.x * tx + tangentDir.y * ty + tangentDir.z * nz;
}

bool coneInsideGrid(vec3 p, ConeTraceParams prm) {
    return all(greaterThanEqual(p, prm.gridMinV0.xyz)) && all(lessThanEqual(p, prm.gridMaxStep.xyz));
}

// The cell size (in v0) the lift clears at level lod: the coarser of the two blended levels,
// 2^ceil(lod) (the exact rule), or with `blend` the two cell sizes mixed by the level's blend
// weight, continuous in t (a partial clearance of the coarse cell, weighted as it is sampled).
float coneLiftCell(float lod, bool blend) {
    return blend ? mix(exp2(floor(lod)), exp2(ceil(lod)), fract(lod)) : exp2(ceil(lod));
}

// Distance from p (inside the grid) along unit n to the grid's boundary (0.99 of it).
float coneExitDistance(vec3 p, vec3 n, ConeTraceParams prm) {
    vec3 lo = (prm.gridMinV0.xyz - p) / n, hi = (prm.gridMaxStep.xyz - p) / n;
    vec3 far = max(lo, hi);  // +inf on axes n does not move along
    return 0.99 * max(min(min(far.x, far.y), far.z), 0.0);
}

// Opacity correction for a step of `ratio` times the level's voxel size (notes 001 §2.9):
// a' = 1 - (1 - a)^ratio. Returns the corrected premultiplied sample; a = 0 gives vec4(0).
vec4 coneCorrectSample(vec4 s, float ratio) {
    float a = clamp(s.a, 0.0, 1.0);
    if (!(a > 1e-6)) return vec4(0.0);
    float corrected = a >= 1.0 ? 1.0 : 1.0 - exp2(ratio * log2(1.0 - a));
    vec3 c = max(s.rgb, vec3(0.0)) * (corrected / a);
    return vec4(c, corrected);
}

// The surface a cone leaves: point x and unit normal n; n = 0 disables the lift.
struct ConeSurface {
    vec3 point;
    vec3 normal;
};

ConeSurface coneNoSurface() { return ConeSurface(vec3(0.0), vec3(0.0)); }

#define CONE_MODE_RADIANCE 0
#define CONE_MODE_OCCLUSION 1

// State of one march (coneMarch).
struct ConeMarchState {
    vec3 color;
    float alpha;
    float t;
    bool done;
};

// One sample of coneMarch at distance st.t; `fine` (a literal at every call, so the compiler
// drops the other sampler) selects voxelConeSample or voxelConeSampleCoarse.
void coneMarchStep(inout ConeMarchState st, bool fine, vec3 origin, vec3 dir, float tanHalf,
                   ConeSurface surface, float maxDistance, int mode, ConeTraceParams p) {
    float v0 = p.gridMinV0.w;
    float cutoff = p.distances.z > 0.0 ? p.distances.z : 1.0;
    if (st.t > maxDistance || st.alpha >= cutoff) {
        st.done = true;
        return;
    }
    float d = coneDiameter(st.t, tanHalf, v0);
    float lod = coneLevel(st.t, tanHalf, p);
    float level = exp2(lod);  // sampled voxel size / v0
    vec3 pos = origin + st.t * dir;
    if (!coneInsideGrid(pos, p)) {  // the axis left the grid: nothing more to gather
        st.done = true;
        return;
    }
    float liftFactor = max(p.misc.y, 0.0) * v0;
    if (liftFactor > 0.0 && dot(surface.normal, surface.normal) > 0.25) {
        // Notes 001 §2.9: the cell of size v0 2^ceil(L) holding the surface stays out of the
        // trilinear footprint when the sample is >= 1.5 cells above the plane.
        float h = dot(pos - surface.point, surface.normal);
        bool blend = p.misc.z > 0.5;
        float need = liftFactor * coneLiftCell(lod, blend) - h;
        if (need > 0.0) {
            // Where the grid ends closer than that along n (an open side of the scene), sample
            // the coarsest level whose lift stays inside instead of empty space.
            float room = coneExitDistance(pos, surface.normal, p);
            if (need > room) {
                lod = min(lod, max(floor(log2(max(h + room, 1e-30) / liftFactor)), 0.0));
                level = exp2(lod);
                need = min(liftFactor * coneLiftCell(lod, blend) - h, room);
            }
            pos += max(need, 0.0) * surface.normal;
        }
    }
    float stepLen = max(p.gridMaxStep.w, 0.01) * d;
    vec4 s = fine ? voxelConeSample(pos, lod, dir) : voxelConeSampleCoarse(pos, lod, dir);
    if (mode == CONE_MODE_OCCLUSION) {
        s = vec4(0.0, 0.0, 0.0, s.a / (1.0 + max(p.distances.w, 0.0) * st.t));
    }
    // d'/d: the step against the voxel size of the sampled level.
    s = coneCorrectSample(s, stepLen / (v0 * level));
    st.color += (1.0 - st.alpha) * s.rgb;
    st.alpha += (1.0 - st.alpha) * s.a;
    st.t += stepLen;
}

// The one cone march every caller shares. mode RADIANCE: rgb = gathered radiance (premultiplied
// front-to-back sum C += (1 - A) c', A += (1 - A) a', notes 001 §8 choice), a = opacity.
// mode OCCLUSION: a = accumulated occlusion of the falloff-weighted opacity f(t) a with
// f = 1 / (1 + lambda t) (Crassin §6; the step correction applies to f a, so the result does
// not depend on the step factor), rgb = 0. Stops at the cutoff, t > maxDistance, when the axis
// leaves the grid or after VOXEL_CONE_MAX_STEPS. Two loops: samples below level 1 (fine: the
// storage may read its finest level), then the rest (coarse), so no sample pays for both.
vec4 coneMarch(vec3 origin, vec3 dir, float tanHalf, ConeSurface surface, float maxDistance,
               int mode, ConeTraceParams p) {
    float len = length(dir);
    float v0 = p.gridMinV0.w;
    if (!(len > 1e-8) || !(v0 > 0.0)) return vec4(0.0);
    dir /= len;
    tanHalf = max(tanHalf, 0.0);
    ConeMarchState st = ConeMarchState(vec3(0.0), 0.0, max(p.distances.y, 0.0), false);
    // The nominal level reaches 1 at t1 (radius 2^(1 - bias) v0).
    float t1 = tanHalf > 0.0 ? exp2(1.0 - p.misc.x) * v0 / tanHalf : 3.0e38;
    int i = 0;
    for (; i < VOXEL_CONE_MAX_STEPS && !st.done && st.t < t1; ++i)
        coneMarchStep(st, true, origin, dir, tanHalf, surface, maxDistance, mode, p);
    for (; i < VOXEL_CONE_MAX_STEPS && !st.done; ++i)
        coneMarchStep(st, false, origin, dir, tanHalf, surface, maxDistance, mode, p);
    return vec4(st.color, clamp(st.alpha, 0.0, 1.0));
}

// A cone from a free point (no surface, no lift): radiance and opacity.
vec4 traceCone(vec3 origin, vec3 dir, float tanHalf, ConeTraceParams p) {
    return coneMarch(origin, dir, tanHalf, coneNoSurface(), p.distances.x, CONE_MODE_RADIANCE, p);
}

// A cone leaving a surface: the origin is offset along n by `offset` (world), samples are lifted.
vec4 traceSurfaceCone(ConeSurface s, float offset, vec3 dir, float tanHalf, ConeTraceParams p) {
    return coneMarch(s.point + offset * s.normal, dir, tanHalf, s, p.distances.x,
                     CONE_MODE_RADIANCE, p);
}

// Ambient-occlusion visibility 1 - delta of one cone (Crassin §6, notes 001 §2.12, notes 003
// E11-E12): delta += (1 - delta) a_f', a_f = f(r) a, f(r) = 1 / (1 + lambda r), r the distance
// along the cone (Crassin's definition; DVS's r = cone radius is the same with lambda = lambda_DVS
// tan(theta/2)), ' the step correction applied to a_f. lambda = 0 gives plain occlusion.
float traceConeOcclusion(vec3 origin, vec3 dir, float tanHalf, ConeTraceParams p) {
    if (!(length(dir) > 1e-8) || !(p.gridMinV0.w > 0.0)) return 1.0;
    return 1.0 - coneMarch(origin, dir, tanHalf, coneNoSurface(), p.distances.x,
                           CONE_MODE_OCCLUSION, p).a;
}

// Occlusion visibility of a cone leaving a surface, up to maxDistance (AO, soft shadows).
float traceSurfaceConeVisibility(ConeSurface s, float offset, vec3 dir, float tanHalf,
                                 float maxDistance, ConeTraceParams p) {
    if (!(length(dir) > 1e-8) || !(p.gridMinV0.w > 0.0)) return 1.0;
    return 1.0 - coneMarch(s.point + offset * s.normal, dir, tanHalf, s, maxDistance,
                           CONE_MODE_OCCLUSION, p).a;
}

#endif  // GILAB_VOXEL_CONE_GLSL
