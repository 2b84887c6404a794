// Storage-independent cone march (docs/voxel_cone_tracing.md; Crassin §5, notes 001 §2.9,
// notes 003 §2.8). Before including, define
//     vec4 voxelConeSample(vec3 worldPos, float lod, vec3 dir);
// returning premultiplied radiance (rgb) and opacity (a) at level `lod` (0 = finest voxel size v0,
// fractional = linear between levels) for a cone travelling along unit `dir`.
// The caller offsets the origin along the surface normal (about 1-2 v0) to avoid self-occlusion.
#ifndef GILAB_VOXEL_CONE_GLSL
#define GILAB_VOXEL_CONE_GLSL

// Safety cap on the samples of one cone (a 512^3 grid traversed at step 0.1 needs far fewer
// because the step grows with the diameter).
#ifndef VOXEL_CONE_MAX_STEPS
#define VOXEL_CONE_MAX_STEPS 1024
#endif

struct ConeTraceParams {
    vec4 gridMinV0;    // xyz grid minimum corner, w = v0 (finest voxel size)
    vec4 gridMaxStep;  // xyz grid maximum corner, w = step factor (d' = step * diameter, E10)
    vec4 distances;    // x max distance (world), y start offset t0 (world), z opacity cutoff,
                       // w AO lambda (1/world units)
    vec4 misc;         // x lod bias (added to coneLod), yzw reserved
};

// Cone diameter at distance t (notes 003 E6), never below the finest voxel size.
float coneDiameter(float t, float tanHalf) {
    return max(2.0 * max(t, 0.0) * max(tanHalf, 0.0), 0.0);
}

// Level whose voxel size matches the diameter (E7); 0 = finest. Safe for d = 0 and v0 = 0.
float coneLod(float diameter, float v0) {
    if (!(diameter > 0.0) || !(v0 > 0.0)) return 0.0;
    return max(0.0, log2(diameter / v0));
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

// Opacity correction for a step of `ratio` times the level's voxel size (notes 001 §2.9):
// a' = 1 - (1 - a)^ratio. Returns the corrected premultiplied sample; a = 0 gives vec4(0).
vec4 coneCorrectSample(vec4 s, float ratio) {
    float a = clamp(s.a, 0.0, 1.0);
    if (!(a > 1e-6)) return vec4(0.0);
    float corrected = a >= 1.0 ? 1.0 : 1.0 - pow(1.0 - a, ratio);
    vec3 c = max(s.rgb, vec3(0.0)) * (corrected / a);
    return vec4(c, corrected);
}

// One cone march. Returns rgb = gathered radiance (premultiplied front-to-back sum,
// C += (1 - A) c', A += (1 - A) a', notes 001 §8 choice), a = accumulated opacity.
// Stops at A >= cutoff, t > max distance, outside the grid or after VOXEL_CONE_MAX_STEPS.
vec4 traceCone(vec3 origin, vec3 dir, float tanHalf, ConeTraceParams p) {
    float len = length(dir);
    if (!(len > 1e-8)) return vec4(0.0);
    dir /= len;
    float v0 = p.gridMinV0.w;
    if (!(v0 > 0.0)) return vec4(0.0);
    float stepFactor = max(p.gridMaxStep.w, 0.01);
    float cutoff = p.distances.z > 0.0 ? p.distances.z : 1.0;
    vec3 color = vec3(0.0);
    float alpha = 0.0;
    float t = max(p.distances.y, 0.0);
    for (int i = 0; i < VOXEL_CONE_MAX_STEPS; ++i) {
        if (t > p.distances.x || alpha >= cutoff) break;
        vec3 pos = origin + t * dir;
        if (!coneInsideGrid(pos, p)) break;
        float d = max(coneDiameter(t, tanHalf), v0);
        float lod = max(coneLod(d, v0) + p.misc.x, 0.0);
        float stepLen = stepFactor * d;
        // d'/d: the step against the voxel size of the sampled level.
        vec4 s = coneCorrectSample(voxelConeSample(pos, lod, dir), stepLen / (v0 * exp2(lod)));
        color += (1.0 - alpha) * s.rgb;
        alpha += (1.0 - alpha) * s.a;
        t += stepLen;
    }
    return vec4(color, clamp(alpha, 0.0, 1.0));
}

// Ambient-occlusion visibility 1 - delta of one cone (Crassin §6, notes 001 §2.12, notes 003
// E11-E12): delta += (1 - delta) a_f', where a_f = f(r) a with f(r) = 1 / (1 + lambda r), r the
// distance along the cone (Crassin's definition; DVS's r = cone radius t tan(theta/2) is the same
// with lambda = lambda_DVS tan(theta/2)), and ' the step correction applied to a_f (E12 applies f after
// the correction, which makes thick occluders depend on the step factor). lambda = 0 gives
// plain occlusion.
float traceConeOcclusion(vec3 origin, vec3 dir, float tanHalf, ConeTraceParams p) {
    float len = length(dir);
    if (!(len > 1e-8)) return 1.0;
    dir /= len;
    float v0 = p.gridMinV0.w;
    if (!(v0 > 0.0)) return 1.0;
    float stepFactor = max(p.gridMaxStep.w, 0.01);
    float cutoff = p.distances.z > 0.0 ? p.distances.z : 1.0;
    float lambda = max(p.distances.w, 0.0);
    float delta = 0.0;
    float t = max(p.distances.y, 0.0);
    for (int i = 0; i < VOXEL_CONE_MAX_STEPS; ++i) {
        if (t > p.distances.x || delta >= cutoff) break;
        vec3 pos = origin + t * dir;
        if (!coneInsideGrid(pos, p)) break;
        float d = max(coneDiameter(t, tanHalf), v0);
        float lod = max(coneLod(d, v0) + p.misc.x, 0.0);
        float stepLen = stepFactor * d;
        // The falloff scales the opacity field (Crassin: alpha_f = f(r) alpha), and the step
        // correction applies to that field, so the result does not depend on the step factor.
        float a = clamp(voxelConeSample(pos, lod, dir).a, 0.0, 1.0) / (1.0 + lambda * t);
        a = coneCorrectSample(vec4(0.0, 0.0, 0.0, a), stepLen / (v0 * exp2(lod))).a;
        delta += (1.0 - delta) * a;
        t += stepLen;
    }
    return clamp(1.0 - delta, 0.0, 1.0);
}

#endif  // GILAB_VOXEL_CONE_GLSL
