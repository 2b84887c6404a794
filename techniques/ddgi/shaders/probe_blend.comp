#version 460
// ddgi "probe_blend_irradiance" / "probe_blend_distance" (paper 1 §4.4; SDK ProbeBlendingCS):
// one thread per interior atlas texel. Texel direction t; over the probe's blended rays
//   irradiance: w = max(0, t.d), E = sum w L / sum w (back faces skipped), stored as E^(1/gamma)
//   distance:   w = max(0, t.d)^s, (mean r, mean r^2) with r = min(|r|, r_max)
// then the hysteresis blend T = alpha T_old + (1 - alpha) T_new. Push constant `distance`
// selects the atlas. The border is written by probe_border.comp afterwards.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#define DDGI_ATLAS_WRITABLE
#include "ddgi_common.glsl"

layout(set = DDGI_SET, binding = 3, std430) readonly buffer ProbeRays { vec4 probeRays[]; };

layout(push_constant) uniform Push {
    uint distance;  // 0 irradiance, 1 distance
} pc;

float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

void main() {
    bool isDistance = pc.distance != 0u;
    uint n = isDistance ? ddgi.texels.y : ddgi.texels.x;
    uint tile = n + 2u;
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    uint tilesX = ddgi.counts.x * ddgi.counts.y;
    if (texel.x >= int(tilesX * tile) || texel.y >= int(ddgi.counts.z * tile)) return;
    ivec2 inTile = texel % int(tile);
    if (inTile.x == 0 || inTile.y == 0 || inTile.x == int(tile) - 1 || inTile.y == int(tile) - 1)
        return;  // border
    ivec2 tileIndex = texel / int(tile);
    uint probe = uint(tileIndex.x) + tilesX * uint(tileIndex.y);
    if (ddgiProbeInactive(probe)) return;

    vec2 uv = (vec2(inTile - ivec2(1)) + 0.5) * (2.0 / float(n)) - 1.0;
    vec3 t = ddgiOctDecode(uv);
    uint raysPerProbe = ddgi.texels.z;
    uint fixedRays = ddgi.texels.w;
    uint first = probe * raysPerProbe;
    float alpha = ddgi.blend.x;

    if (!isDistance) {
        uint backFaces = 0u;
        vec3 sumL = vec3(0.0);
        float sumW = 0.0;
        for (uint r = fixedRays; r < raysPerProbe; ++r) {
            vec4 ray = probeRays[first + r];
            if (ray.w < 0.0) {
                ++backFaces;
                continue;
            }
            float w = dot(t, ddgiRayDirection(r));
            if (w <= 0.0) continue;
            sumL += w * ray.rgb;
            sumW += w;
        }
        // Probably inside geometry: leave the texel as it is (SDK)
        if (float(backFaces) >= ddgi.thresholds.w * float(raysPerProbe - fixedRays)) return;
        if (sumW <= 1e-6) return;
        vec3 eNew = pow(max(sumL / sumW, vec3(0.0)), vec3(1.0 / ddgi.blend.y));
        vec3 eOld = imageLoad(irradianceAtlas, texel).rgb;
        vec3 delta = eNew - eOld;
        // SDK transition heuristics (0 = off)
        if (ddgi.thresholds.x > 0.0 && max(abs(delta.r), max(abs(delta.g), abs(delta.b))) >
                                           ddgi.thresholds.x)
            alpha = max(0.0, alpha - 0.75);
        vec3 step = (1.0 - alpha) * delta;
        if (ddgi.thresholds.y > 0.0 && luminance(delta) > ddgi.thresholds.y) step *= 0.25;
        imageStore(irradianceAtlas, texel, vec4(eOld + step, 1.0));
    } else {
        float rMax = ddgi.gridSpacing.w;
        float s = ddgi.blend.z;
        vec2 sum = vec2(0.0);
        float sumW = 0.0;
        for (uint r = fixedRays; r < raysPerProbe; ++r) {
            float c = dot(t, ddgiRayDirection(r));
            if (c <= 0.0) continue;
            float w = pow(c, s);
            float d = min(abs(probeRays[first + r].w), rMax);
            sum += w * vec2(d, d * d);
            sumW += w;
        }
        if (sumW <= 1e-12) return;
        vec2 mNew = sum / sumW;
        vec2 mOld = imageLoad(distanceAtlas, texel).xy;
        imageStore(distanceAtlas, texel, vec4(mix(mNew, mOld, alpha), 0.0, 1.0));
    }
}
