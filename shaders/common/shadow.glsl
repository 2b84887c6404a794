// Shadow-map lookups for the pass light table (lights.glsl). Include after #version.
//
// Every map stores the LINEAR distance from the light to the nearest surface (R32F):
//   perspective maps (spot 2D, point / wide-spot / emitter-sample cubes): |p - lightPosition|
//   orthographic maps (directional, and its view-fitted cascades): dot(p - origin, direction)
//   from the scene bounds' entry plane.
// Cube maps are stored in cube-array images (layer = 6 * cube + face) but read here through a
// 2D-array view with the Vulkan face table (spec "Cube Map Face Selection"), so PCF taps are in
// texels of one face (taps past a face edge are clamped to it).
//
// Two lookups (docs/shared_passes.md, "Lookup and bias"):
//   shadowVisibilitySurface  a point of a rasterised triangle with its geometric normal (the
//                            direct pass): each texel is compared with the distance at which the
//                            texel's own ray meets the receiver's plane, and a directional light
//                            is looked up in its view-fitted cascades first
//   shadowVisibility         any other point (voxel centres): the receiver is moved along its
//                            normal and a slope-scaled bias absorbs the receiver's own depth
//
// Options (define before #include):
//   SHADOW_SET n       descriptor set of the bindings below (default 1)
//   SHADOW_BINDING n   first of the 4 bindings (default 0):
//     +0 PassLight[]        readonly SSBO (the lights, then the cascade entries)
//     +1 sampler2DArray     the 2D maps (spot, directional, cascades)
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

// Vulkan cube face axes (s, t, major), as kCubeFaces in core/passes/light_view.h: face f was
// rendered with framebuffer (x, y) / size = (s, t) and direction = m + ndc.x * s + ndc.y * t.
const vec3 kShadowCubeS[6] = vec3[6](vec3(0, 0, -1), vec3(0, 0, 1), vec3(1, 0, 0),
                                     vec3(1, 0, 0), vec3(1, 0, 0), vec3(-1, 0, 0));
const vec3 kShadowCubeT[6] = vec3[6](vec3(0, -1, 0), vec3(0, -1, 0), vec3(0, 0, 1),
                                     vec3(0, 0, -1), vec3(0, -1, 0), vec3(0, -1, 0));
const vec3 kShadowCubeM[6] = vec3[6](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0),
                                     vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));

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

ivec2 shadowMapSize(int kind) {
    return kind == SHADOW_MAP_2D ? textureSize(shadowMaps2D, 0).xy
           : kind == SHADOW_CUBE ? textureSize(shadowCubes, 0).xy
                                 : textureSize(shadowAreaCubes, 0).xy;
}

float shadowFetch(int kind, ivec3 t) {
    return kind == SHADOW_MAP_2D ? texelFetch(shadowMaps2D, t, 0).r
           : kind == SHADOW_CUBE ? texelFetch(shadowCubes, t, 0).r
                                 : texelFetch(shadowAreaCubes, t, 0).r;
}

// tan(theta) of the receiver toward the light, clamped to 10 (84 deg).
float shadowTanTheta(vec3 n, vec3 wi) {
    float cosTheta = clamp(dot(n, wi), 1.0e-4, 1.0);
    return min(sqrt(max(1.0 - cosTheta * cosTheta, 0.0)) / cosTheta, 10.0);
}

// The taps of one layer around x's projection (continuous texel coordinates texelPos), each
// compared with the receiver's distance at that tap:
//   offset mode (plane false): d(x) for every tap;
//   plane mode: min(d(x), the distance at which the ray of the tap's texel centre c meets the
//     plane through x with normal ng). Where the plane comes toward the light, that is exactly
//     what c sees of a planar receiver, so no slope bias is needed at any angle; where it
//     recedes, anything c sees beyond x's own distance cannot shadow x (at grazing angles c's
//     ray may pass beside the receiver and land on the floor behind it). Orthographic maps: the
//     distance changes by `gradient` per texel; perspective maps: c's ray from the light runs
//     along axisM + ndc.x * axisS + ndc.y * axisT.
float shadowTaps(int kind, int layer, vec2 texelPos, float receiverDistance, bool plane,
                 bool ortho, vec2 gradient, bool gradientValid, vec3 lightToX, vec3 ng,
                 vec3 axisM, vec3 axisS, vec3 axisT, float bias, int radius) {
    ivec2 size = shadowMapSize(kind);
    ivec2 center = clamp(ivec2(floor(texelPos)), ivec2(0), size - 1);
    float planeNumerator = dot(ng, lightToX);
    float lit = 0.0;
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            ivec2 c = clamp(center + ivec2(dx, dy), ivec2(0), size - 1);
            float expected = receiverDistance;
            if (plane) {
                float delta = 0.0;  // edge-on plane: it does not meet c's ray
                if (ortho) {
                    if (gradientValid) delta = dot(gradient, vec2(c) + 0.5 - texelPos);
                } else {
                    vec2 ndc = 2.0 * (vec2(c) + 0.5) / vec2(size) - 1.0;
                    vec3 dir = normalize(axisM + ndc.x * axisS + ndc.y * axisT);
                    float denom = dot(ng, dir);
                    if (denom * planeNumerator > 0.0) delta = planeNumerator / denom - expected;
                }
                // Only a plane coming toward the light lowers the threshold: where it recedes,
                // whatever c sees beyond x's own distance is no occluder of x.
                expected += min(delta, 0.0);
            }
            lit += shadowFetch(kind, ivec3(c, layer)) >= expected - bias ? 1.0 : 0.0;
        }
    }
    float taps = float((2 * radius + 1) * (2 * radius + 1));
    return lit / taps;
}

// Visibility of one map (a light's own map or one of its cascades) from x:
//   n         unit normal facing the light side (dot(n, wi) > 0): normal offset and slope
//   ng        unit geometric normal (either side) for the plane mode
//   settings  x constant bias, y slope bias (texels, per unit tan(theta)), z normal offset
//             (texels per PCF radius + 1), w PCF radius
// Offset mode (plane false): x' = x + n * normalOffset * (radius + 1) * texel, and a tap is lit if
// stored >= d(x') - (constant + slope * min(tan(theta), 10)) * texel. Moving x by h along n gives
// a margin of h / cos(theta) along the light ray, which grows faster than the tan(theta) * texel
// per texel that PCF taps see on a tilted receiver.
// Returns -1 when `needInside` is set and x's PCF footprint is not inside a 2D map.
float shadowLookup(PassLight light, vec3 x, vec3 n, vec3 ng, vec3 wi, vec4 settings, bool plane,
                   bool needInside) {
    int kind = int(light.shadow.x);
    if (kind == SHADOW_NONE) return 1.0;
    bool ortho = light.shadow.w > 0.5;
    vec3 lightPos = light.positionType.xyz;
    float texel = light.shadow.z * (ortho ? 1.0 : length(x - lightPos));
    int radius = int(settings.w);
    vec3 xo = x + n * (settings.z * float(radius + 1) * texel);
    vec3 lightToX = xo - lightPos;
    float d = ortho ? dot(xo - light.origin.xyz, light.direction.xyz) : length(lightToX);
    // Tolerance: the settings (plane mode: plus the floating-point error of both distances)
    float bias = texel * (settings.x + settings.y * shadowTanTheta(n, wi));
    if (plane) bias += 1.0e-5 * (abs(d) + length(x));

    if (kind == SHADOW_MAP_2D) {
        float outside = needInside ? -1.0 : 1.0;
        vec4 clip = light.viewProj * vec4(xo, 1.0);
        if (clip.w <= 0.0) return outside;
        vec2 size = vec2(shadowMapSize(kind));
        vec2 texelPos = (0.5 * (clip.xy / clip.w) + 0.5) * size;
        float margin = needInside ? float(radius) + 1.0 : 0.0;
        if (any(lessThan(texelPos, vec2(margin))) || any(greaterThan(texelPos, size - margin)))
            return outside;
        // Rows of viewProj (xyz): clip.x = r0.p, clip.y = r1.p, clip.w = r3.p (+ constants)
        vec3 r0 = vec3(light.viewProj[0][0], light.viewProj[1][0], light.viewProj[2][0]);
        vec3 r1 = vec3(light.viewProj[0][1], light.viewProj[1][1], light.viewProj[2][1]);
        vec3 r3 = vec3(light.viewProj[0][3], light.viewProj[1][3], light.viewProj[2][3]);
        int layer = int(light.shadow.y);
        if (ortho) {
            // A texel step moves the ray by r0 / |r0|^2 / (size / 2) (the rows are orthogonal to
            // the light direction l); the plane's distance then changes by -ng.step / ng.l.
            float ngl = dot(ng, light.direction.xyz);
            bool valid = abs(ngl) > 1.0e-6;
            vec2 gradient = valid ? -vec2(dot(ng, r0) / dot(r0, r0), dot(ng, r1) / dot(r1, r1)) /
                                        (0.5 * size * ngl)
                                  : vec2(0.0);
            return shadowTaps(kind, layer, texelPos, d, plane, true, gradient, valid, lightToX, ng,
                              vec3(0.0), vec3(0.0), vec3(0.0), bias, radius);
        }
        // Pinhole rows (light_view.h): the ray through ndc (u, v) runs along
        // r3 + (u r0 + v r1) / |r0|^2.
        float inv = 1.0 / dot(r0, r0);
        return shadowTaps(kind, layer, texelPos, d, plane, false, vec2(0.0), false, lightToX,
                          ng, r3, r0 * inv, r1 * inv, bias, radius);
    }
    vec2 st;
    int face = cubeFace(lightToX, st);
    return shadowTaps(kind, int(light.shadow.y) * 6 + face, st * vec2(shadowMapSize(kind)), d,
                      plane, false, vec2(0.0), false, lightToX, ng, kShadowCubeM[face],
                      kShadowCubeS[face], kShadowCubeT[face], bias, radius);
}

// Visibility in [0, 1] of light `light` from a point x that is not on a rasterised surface
// (a voxel centre), with unit normal n facing the light side (dot(n, wi) > 0): the offset mode
// with the light's volume settings (PassLight.bias).
float shadowVisibility(PassLight light, vec3 x, vec3 n, vec3 wi) {
    return shadowLookup(light, x, n, vec3(0.0), wi, light.bias, false, false);
}

// Visibility in [0, 1] of pass light `index` from a point x of a rasterised triangle:
//   n   unit shading normal facing the light side (dot(n, wi) > 0)
//   ng  unit geometric normal of the triangle (either side; zero if unknown: offset mode)
// Uses the light's surface settings (PassLight.surfaceBias; the plane mode when
// PassLight.cascades.z is set) and, for a directional light, the first of its view-fitted
// cascades (PassLight.cascades.xy) that holds x's PCF footprint, else the light's own map.
float shadowVisibilitySurface(uint index, vec3 x, vec3 n, vec3 ng, vec3 wi) {
    PassLight light = passLights[index];
    if (int(light.shadow.x) == SHADOW_NONE) return 1.0;
    vec4 settings = light.surfaceBias;
    bool plane = light.cascades.z > 0.5 && dot(ng, ng) > 0.0;
    uint first = uint(light.cascades.x);
    uint count = uint(light.cascades.y);
    float band = light.cascades.w;
    for (uint k = 0u; k < count; ++k) {
        PassLight c = passLights[first + k];
        float v = shadowLookup(c, x, n, ng, wi, settings, plane, true);
        if (v < 0.0) continue;
        // Blend band (shared.shadow_cascade_blend): within `band` of the half-size from the
        // cascade's border, fade into the next cascade that holds x (else the light's own map),
        // so a receiver crossing the border changes gradually instead of switching texel grids
        vec4 clip = c.viewProj * vec4(x, 1.0);
        float edge = clip.w > 0.0 ? 1.0 - max(abs(clip.x), abs(clip.y)) / clip.w : 1.0;
        if (band > 0.0 && edge < band) {
            float next = -1.0;
            for (uint j = k + 1u; j < count && next < 0.0; ++j)
                next = shadowLookup(passLights[first + j], x, n, ng, wi, settings, plane, true);
            if (next < 0.0) next = shadowLookup(light, x, n, ng, wi, settings, plane, false);
            v = mix(next, v, clamp(edge / band, 0.0, 1.0));
        }
        return v;
    }
    return shadowLookup(light, x, n, ng, wi, settings, plane, false);
}

#endif  // GILAB_SHADOW_GLSL
