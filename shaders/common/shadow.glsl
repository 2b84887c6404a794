// Shadow-map lookups for the pass light table (lights.glsl). Include after #version.
//
// Every map stores the LINEAR distance from the light to the nearest surface (R32F):
//   perspective maps (spot 2D, point / wide-spot / emitter-sample cubes): |p - lightPosition|
//   orthographic maps (directional): dot(p - origin, direction) from the bounds' entry plane.
// Cube maps are stored in cube-array images (layer = 6 * cube + face) but read here through a
// 2D-array view with the Vulkan face table (spec "Cube Map Face Selection"), so PCF taps are in
// texels of one face (taps past a face edge are clamped to it).
//
// Options (define before #include):
//   SHADOW_SET n       descriptor set of the bindings below (default 1)
//   SHADOW_BINDING n   first of the 4 bindings (default 0):
//     +0 PassLight[]        readonly SSBO
//     +1 sampler2DArray     the 2D maps (spot, directional)
//     +2 sampler2DArray     the cube maps of point lights and wide spots (6 layers per cube)
//     +3 sampler2DArray     the cube maps of the emitter samples
#ifndef GILAB_SHADOW_GLSL
#define GILAB_SHADOW_GLSL

#include "common/lights.glsl"

#ifndef SHADOW_SET
#define SHADOW_SET 1
#endif
#ifndef SHADOW_BINDING
#define SHADOW_BINDING 0
#endif

layout(set = SHADOW_SET, binding = SHADOW_BINDING + 0, std430) readonly buffer PassLights {
    PassLight passLights[];
};
layout(set = SHADOW_SET, binding = SHADOW_BINDING + 1) uniform sampler2DArray shadowMaps2D;
layout(set = SHADOW_SET, binding = SHADOW_BINDING + 2) uniform sampler2DArray shadowCubes;
layout(set = SHADOW_SET, binding = SHADOW_BINDING + 3) uniform sampler2DArray shadowAreaCubes;

uint passLightCount() { return uint(passLights.length()); }

// Vulkan cube face of direction r and its (s, t) in [0, 1]; core/passes/shadow_maps.cpp renders
// face f with the same (sc, tc, ma) axes.
int cubeFace(vec3 r, out vec2 st) {
    vec3 a = abs(r);
    int face;
    float sc, tc, ma;
    if (a.x >= a.y && a.x >= a.z) {
        face = r.x >= 0.0 ? 0 : 1;
        sc = r.x >= 0.0 ? -r.z : r.z;
        tc = -r.y;
        ma = a.x;
    } else if (a.y >= a.z) {
        face = r.y >= 0.0 ? 2 : 3;
        sc = r.x;
        tc = r.y >= 0.0 ? r.z : -r.z;
        ma = a.y;
    } else {
        face = r.z >= 0.0 ? 4 : 5;
        sc = r.z >= 0.0 ? r.x : -r.x;
        tc = -r.y;
        ma = a.z;
    }
    st = 0.5 * (vec2(sc, tc) / ma + 1.0);
    return face;
}

// Percentage-closer filtering over (2r+1)^2 texels around uv of one layer: the fraction of taps
// whose stored distance is >= receiverDistance - bias.
float shadowPcf(int kind, vec2 uv, int layer, float receiverDistance, float bias, int radius) {
    ivec2 size = kind == SHADOW_MAP_2D ? textureSize(shadowMaps2D, 0).xy
                 : kind == SHADOW_CUBE ? textureSize(shadowCubes, 0).xy
                                       : textureSize(shadowAreaCubes, 0).xy;
    ivec2 center = clamp(ivec2(floor(uv * vec2(size))), ivec2(0), size - 1);
    float lit = 0.0;
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            ivec3 t = ivec3(clamp(center + ivec2(dx, dy), ivec2(0), size - 1), layer);
            float stored = kind == SHADOW_MAP_2D ? texelFetch(shadowMaps2D, t, 0).r
                           : kind == SHADOW_CUBE ? texelFetch(shadowCubes, t, 0).r
                                                 : texelFetch(shadowAreaCubes, t, 0).r;
            lit += stored >= receiverDistance - bias ? 1.0 : 0.0;
        }
    }
    float taps = float((2 * radius + 1) * (2 * radius + 1));
    return lit / taps;
}

// Visibility in [0, 1] of light `light` from the surface point x with unit normal n (facing
// the light side the caller shades; wi = unit direction toward the light, dot(n, wi) > 0).
// Bias, in texels of the map at x (texel = the map's texel footprint at x's distance):
//   x' = x + n * normalOffset * (pcfRadius + 1) * texel
//   lit if stored >= d(x') - (constant + slope * min(tan(theta), 10)) * texel
// Moving x by h along n gives a margin of h / cos(theta) along the light ray, which grows
// faster than the tan(theta) * texel per texel that PCF taps see on a tilted receiver, so the
// normal offset alone keeps grazing receivers free of acne.
float shadowVisibility(PassLight light, vec3 x, vec3 n, vec3 wi) {
    int kind = int(light.shadow.x);
    if (kind == SHADOW_NONE) return 1.0;
    bool ortho = light.shadow.w > 0.5;
    float dist = ortho ? 1.0 : length(x - light.positionType.xyz);
    float texel = light.shadow.z * dist;
    float cosTheta = clamp(dot(n, wi), 1.0e-4, 1.0);
    float tanTheta = min(sqrt(max(1.0 - cosTheta * cosTheta, 0.0)) / cosTheta, 10.0);
    int radius = int(light.bias.w);
    float bias = texel * (light.bias.x + light.bias.y * tanTheta);
    vec3 xo = x + n * (light.bias.z * float(radius + 1) * texel);

    if (kind == SHADOW_MAP_2D) {
        vec4 clip = light.viewProj * vec4(xo, 1.0);
        if (clip.w <= 0.0) return 1.0;
        vec2 uv = 0.5 * (clip.xy / clip.w) + 0.5;
        if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;
        float d = ortho ? dot(xo - light.origin.xyz, light.direction.xyz)
                        : length(xo - light.positionType.xyz);
        return shadowPcf(kind, uv, int(light.shadow.y), d, bias, radius);
    }
    vec3 r = xo - light.positionType.xyz;
    vec2 st;
    int face = cubeFace(r, st);
    return shadowPcf(kind, st, int(light.shadow.y) * 6 + face, length(r), bias, radius);
}

#endif  // GILAB_SHADOW_GLSL
