// ddgi: the probe volume's uniforms, bindings and the per-point irradiance query (notes 005
// §2, §3.6; techniques/ddgi/README.md). Mirrored by DdgiUniforms in techniques/ddgi/ddgi_volume.cpp.
//
// Set 1 (every ddgi pass; each shader declares what it uses before including this file):
//   0 uniforms   1 irradiance atlas   2 distance atlas   3 probe rays   4 probe data
//   5-8 G-buffer (gather)   9 indirect (gather)   10-11 BVH   12-15 pass lights (shadow set)
//   16 this update's ray directions
// Define DDGI_ATLAS_WRITABLE in the passes that write the atlases, DDGI_PROBES_WRITABLE in the
// passes that write the probe data.
#ifndef DDGI_COMMON_GLSL
#define DDGI_COMMON_GLSL

#define DDGI_SET 1
#define DDGI_PI 3.14159265358979

layout(set = DDGI_SET, binding = 0, std140) uniform DdgiUniforms {
    vec4 gridOrigin;   // xyz: position of probe (0, 0, 0); w: min spacing
    vec4 gridSpacing;  // xyz: spacing; w: r_max (stored distances are clamped to it)
    uvec4 counts;      // xyz probes per axis; w total
    uvec4 texels;      // x irradiance interior, y distance interior, z rays per probe, w fixed rays
    uvec4 lights;      // x punctual lights, y emitter samples, z samples per hit, w frame index
    uvec4 flags;       // x feedback, y emission in probes, z relocation, w classification
    vec4 blend;        // x hysteresis (this update), y gamma, z distance exponent, w energy preservation
    vec4 bias;         // x mode (0 self shadow, 1 normal/view), y self-shadow length, z b_n, w b_v
    vec4 thresholds;   // x irradiance, y brightness, z back-face (fixed rays), w back-face (texel)
    vec4 misc;         // x ray epsilon, y min front-face distance, z hit texture lod, w Chebyshev floor
    vec4 camera;       // xyz eye
    mat4 rotation;     // this update's random rotation of the ray set (for reference)
    uvec4 size;        // x width, y height, z seed
} ddgi;

#ifdef DDGI_ATLAS_WRITABLE
layout(set = DDGI_SET, binding = 1, rgba32f) uniform image2D irradianceAtlas;
layout(set = DDGI_SET, binding = 2, rgba32f) uniform image2D distanceAtlas;
#else
layout(set = DDGI_SET, binding = 1, rgba32f) readonly uniform image2D irradianceAtlas;
layout(set = DDGI_SET, binding = 2, rgba32f) readonly uniform image2D distanceAtlas;
#endif

#ifdef DDGI_PROBES_WRITABLE
layout(set = DDGI_SET, binding = 4, std430) buffer ProbeData { vec4 probeData[]; };
#else
layout(set = DDGI_SET, binding = 4, std430) readonly buffer ProbeData { vec4 probeData[]; };
#endif

#define DDGI_PROBE_ACTIVE 0.0
#define DDGI_PROBE_INACTIVE 1.0

// ---- octahedral maps (Cigolle et al. 2014; SDK ProbeOctahedral) ------------------------------

vec2 ddgiSignNotZero(vec2 v) {
    return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

// Unit direction -> [-1, 1]^2.
vec2 ddgiOctEncode(vec3 d) {
    vec2 uv = d.xy / (abs(d.x) + abs(d.y) + abs(d.z));
    if (d.z < 0.0) uv = (1.0 - abs(uv.yx)) * ddgiSignNotZero(uv);
    return uv;
}

vec3 ddgiOctDecode(vec2 uv) {
    vec3 d = vec3(uv, 1.0 - abs(uv.x) - abs(uv.y));
    if (d.z < 0.0) d.xy = (1.0 - abs(d.yx)) * ddgiSignNotZero(d.xy);
    return normalize(d);
}

// ---- probes ----------------------------------------------------------------------------------

ivec3 ddgiProbeCoords(uint index) {
    uint cx = ddgi.counts.x, cy = ddgi.counts.y;
    return ivec3(index % cx, (index / cx) % cy, index / (cx * cy));
}

uint ddgiProbeIndex(ivec3 c) {
    return uint(c.x) + ddgi.counts.x * (uint(c.y) + ddgi.counts.y * uint(c.z));
}

// Grid position plus the relocation offset (zero when relocation is off).
vec3 ddgiProbePosition(uint index) {
    return ddgi.gridOrigin.xyz + ddgi.gridSpacing.xyz * vec3(ddgiProbeCoords(index)) +
           probeData[index].xyz;
}

bool ddgiProbeInactive(uint index) {
    return ddgi.flags.w != 0u && probeData[index].w == DDGI_PROBE_INACTIVE;
}

// Top-left texel of a probe's tile (interior n + 2 border): tiles run x, then y along the atlas
// width and z down its height (the G3D layout).
ivec2 ddgiTileOrigin(uint index, uint interior) {
    ivec3 c = ddgiProbeCoords(index);
    int tile = int(interior) + 2;
    return ivec2((c.x + c.y * int(ddgi.counts.x)) * tile, c.z * tile);
}

// ---- ray directions (notes 005 §3.1) --------------------------------------------------------

// Ray r of every probe this update, written by the CPU each update (DdgiVolume::setFrame): the
// fixed rays (relocation, classification) are an un-rotated spherical-Fibonacci set; the others
// a set of their own, rotated by this update's random rotation (SDK).
layout(set = DDGI_SET, binding = 16, std430) readonly buffer RayDirections { vec4 rayDirections[]; };

vec3 ddgiRayDirection(uint r) {
    return rayDirections[r].xyz;
}

// ---- atlas lookups (software bilinear within a tile; the border makes it seamless) ----------

vec4 ddgiBilinear(bool irradiance, uint index, vec3 dir) {
    uint n = irradiance ? ddgi.texels.x : ddgi.texels.y;
    vec2 uv = ddgiOctEncode(dir);
    vec2 f = (uv * 0.5 + 0.5) * float(n) - 0.5 + 1.0;  // tile coordinates, texel centres at ints
    f = clamp(f, vec2(0.0), vec2(float(n) + 1.0));
    ivec2 p0 = ivec2(floor(f));
    vec2 w = f - vec2(p0);
    ivec2 o = ddgiTileOrigin(index, n);
    ivec2 hi = o + ivec2(int(n) + 1);
    ivec2 a = min(o + p0, hi), b = min(o + p0 + ivec2(1), hi);
    vec4 t00, t10, t01, t11;
    if (irradiance) {
        t00 = imageLoad(irradianceAtlas, ivec2(a.x, a.y));
        t10 = imageLoad(irradianceAtlas, ivec2(b.x, a.y));
        t01 = imageLoad(irradianceAtlas, ivec2(a.x, b.y));
        t11 = imageLoad(irradianceAtlas, ivec2(b.x, b.y));
    } else {
        t00 = imageLoad(distanceAtlas, ivec2(a.x, a.y));
        t10 = imageLoad(distanceAtlas, ivec2(b.x, a.y));
        t01 = imageLoad(distanceAtlas, ivec2(a.x, b.y));
        t11 = imageLoad(distanceAtlas, ivec2(b.x, b.y));
    }
    return mix(mix(t00, t10, w.x), mix(t01, t11, w.x), w.y);
}

// ---- the query (sampleIrradiance, notes 005 §3.6) --------------------------------------------

// Irradiance E(x, n) from the 8 probes of the cell around the biased point; wo = unit vector
// from x toward the viewer (for probe rays: -ray direction). Returns W/m^2 (x pi: the blend
// stores the cosine-weighted mean radiance).
vec3 ddgiIrradiance(vec3 x, vec3 n, vec3 wo) {
    vec3 biasVector = ddgi.bias.x < 0.5 ? (0.2 * n + 0.8 * wo) * ddgi.bias.y
                                         : n * ddgi.bias.z + wo * ddgi.bias.w;
    vec3 xb = x + biasVector;
    ivec3 maxCoord = ivec3(ddgi.counts.xyz) - 1;
    vec3 spacing = ddgi.gridSpacing.xyz;
    ivec3 base = clamp(ivec3(floor((xb - ddgi.gridOrigin.xyz) / spacing)), ivec3(0), maxCoord);
    vec3 basePos = ddgi.gridOrigin.xyz + spacing * vec3(base);
    vec3 alpha = clamp((xb - basePos) / spacing, vec3(0.0), vec3(1.0));
    float gammaHalf = 0.5 * ddgi.blend.y;

    vec3 sumE = vec3(0.0);
    float sumW = 0.0;
    for (int c = 0; c < 8; ++c) {
        ivec3 offset = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        ivec3 coords = min(base + offset, maxCoord);
        uint index = ddgiProbeIndex(coords);
        if (ddgiProbeInactive(index)) continue;
        vec3 p = ddgiProbePosition(index);
        // Trilinear, each factor >= 0.001 (SDK)
        vec3 tri = mix(vec3(1.0) - alpha, alpha, vec3(offset));
        float trilinear = max(tri.x, 0.001) * max(tri.y, 0.001) * max(tri.z, 0.001);
        // Smooth back-face ("wrap") term, from the unbiased point
        vec3 toProbe = p - x;
        float lenToProbe = length(toProbe);
        vec3 u = lenToProbe > 1e-6 ? toProbe / lenToProbe : n;
        float wrap = (dot(u, n) + 1.0) * 0.5;
        float w = wrap * wrap + 0.2;
        // Chebyshev visibility on the distance moments, from the biased point
        vec3 v = xb - p;
        float d = length(v);
        vec2 moments = ddgiBilinear(false, index, d > 1e-6 ? v / d : n).xy;
        float variance = abs(moments.x * moments.x - moments.y);
        if (d > moments.x) {
            float diff = d - moments.x;
            float cheb = variance / max(variance + diff * diff, 1e-12);
            cheb = cheb * cheb * cheb;
            w *= max(cheb, ddgi.misc.w);
        }
        w = max(w, 1e-6);
        // Crush tiny weights (perception is logarithmic, paper-era code and SDK)
        const float crush = 0.2;
        if (w < crush) w *= w * w / (crush * crush);
        w *= trilinear;
        // Blend sqrt(E): stored S = E^(1/gamma), so S^(gamma/2)
        vec3 s = max(ddgiBilinear(true, index, n).rgb, vec3(0.0));
        sumE += w * pow(s, vec3(gammaHalf));
        sumW += w;
    }
    if (!(sumW > 0.0)) return vec3(0.0);
    vec3 e = sumE / sumW;
    return e * e * DDGI_PI;
}

#endif  // DDGI_COMMON_GLSL
