#version 460
#extension GL_GOOGLE_include_directive : require
// Direct light (core/passes/direct_light.cpp): one thread per pixel,
//   direct.rgb = sum over the punctual lights of f(wi, wo) * E_perp * max(0, n.wi) * V
//              + area lights
// with wo toward the camera, f from brdf.glsl, E_perp from lights.glsl and V from shadow.glsl
// (surface receivers: the triangle's plane from the scene set, view-fitted cascades).
// Area lights (emitter samples k): S = sum_k f_k E_k V_k, and with the analytic option
//   S * E_exact / sum_k E_k   per channel (the ratio estimator of Heitz et al. 2018),
// where E_exact is the unoccluded irradiance of every emissive triangle from Lambert's polygon
// formula (exact), so the samples only carry the visibility and the BRDF's variation.
// No ambient term, no clamping. direct.a = 1 on covered pixels, 0 on the background.
#include "common/brdf.glsl"
#include "common/scene.glsl"
#define SHADOW_SET 1
#define SHADOW_BINDING 6
#include "common/shadow.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 1, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 1, binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(set = 1, binding = 3, rgba32f) uniform readonly image2D gMaterial;
layout(set = 1, binding = 4, rgba32f) uniform writeonly image2D outDirect;
// Emissive triangles, 4 vec4 each: p0 (w 1 = two-sided), p1, p2, radiance
layout(set = 1, binding = 5, std430) readonly buffer EmitterPolygons { vec4 emitterPolygons[]; };

layout(push_constant, std430) uniform DirectPush {
    vec4 cameraPosition;  // xyz world
    uvec4 sizeLights;     // x width, y height, z light count, w 1 = shadows on
    uvec4 areaLights;     // x first emitter-sample entry, y emissive triangles (0 = no analytic)
} pc;

// Irradiance at x (unit normal n) from a Lambertian polygon of unit radiance, unoccluded:
// Lambert's formula E = 1/2 |sum_i Theta_i (n . Gamma_i)| (Arvo 1995, eq. 6) over the part of
// the triangle above x's tangent plane (clipped, so at most 4 vertices).
float triangleIrradiance(vec3 x, vec3 n, vec3 a, vec3 b, vec3 c) {
    vec3 p[3] = vec3[3](a - x, b - x, c - x);
    float h[3] = float[3](dot(n, p[0]), dot(n, p[1]), dot(n, p[2]));
    vec3 v[4];
    int count = 0;
    for (int i = 0; i < 3; ++i) {
        int j = (i + 1) % 3;
        if (h[i] >= 0.0) v[count++] = p[i];
        if ((h[i] >= 0.0) != (h[j] >= 0.0)) v[count++] = mix(p[i], p[j], h[i] / (h[i] - h[j]));
    }
    if (count < 3) return 0.0;
    float sum = 0.0;
    for (int i = 0; i < count; ++i) {
        vec3 u = v[i], w = v[(i + 1) % count];
        vec3 cr = cross(u, w);
        float s = length(cr);
        if (s > 0.0) sum += atan(s, dot(u, w)) * dot(n, cr) / s;
    }
    return 0.5 * abs(sum);
}

// Unoccluded irradiance at x from every emissive triangle (front faces, or both when
// two-sided); triangles whose plane holds x give nothing.
vec3 emitterIrradiance(vec3 x, vec3 n) {
    vec3 e = vec3(0.0);
    for (uint t = 0u; t < pc.areaLights.y; ++t) {
        vec4 a = emitterPolygons[4u * t], b = emitterPolygons[4u * t + 1u];
        vec4 c = emitterPolygons[4u * t + 2u];
        vec3 ne = cross(b.xyz - a.xyz, c.xyz - a.xyz);
        float side = dot(ne, x - a.xyz);
        float scale = length(ne) * (length(x - a.xyz) + length(b.xyz - a.xyz));
        if (abs(side) <= 1.0e-6 * scale || (side < 0.0 && a.w < 0.5)) continue;
        e += emitterPolygons[4u * t + 3u].rgb * triangleIrradiance(x, n, a.xyz, b.xyz, c.xyz);
    }
    return e;
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.sizeLights.x) || pixel.y >= int(pc.sizeLights.y)) return;

    vec4 position = imageLoad(gPosition, pixel);
    if (position.w <= 0.0) {
        imageStore(outDirect, pixel, vec4(0.0));
        return;
    }
    vec3 x = position.xyz;
    vec3 n = imageLoad(gNormal, pixel).xyz;
    vec3 albedo = imageLoad(gAlbedo, pixel).rgb;
    vec4 material = imageLoad(gMaterial, pixel);
    vec2 metalRough = material.xy;
    vec3 wo = normalize(pc.cameraPosition.xyz - x);
    // The receiver's plane: its triangle (G-buffer material.w = triangle id + 1)
    vec3 ng = vec3(0.0);
    if (material.w >= 1.0) {
        vec3 c = triangleGeometricNormal(uint(material.w) - 1u);
        float len = length(c);
        if (len > 0.0) ng = c / len;
        if (dot(ng, wo) < 0.0) ng = -ng;  // the side the viewer sees (as n, gbuffer.frag)
    }

    // Sum f * E * V over the lights; the emitter samples are gathered apart (area lights)
    vec3 radiance = vec3(0.0);
    vec3 areaShadowed = vec3(0.0), areaUnoccluded = vec3(0.0);
    for (uint i = 0u; i < pc.sizeLights.z; ++i) {
        PassLight light = passLights[i];
        vec3 wi;
        float dist;
        vec3 ePerp = lightIrradiancePerp(light, x, wi, dist);
        float cosTheta = dot(n, wi);
        if (cosTheta <= 0.0 || all(equal(ePerp, vec3(0.0)))) continue;
        // A light behind the seen side of the triangle reaches it through the surface only: a
        // smooth shading normal may still face it (the path tracer's rule, integrator.cpp)
        if (dot(ng, wi) < 0.0) continue;
        bool isSample = i >= pc.areaLights.x;
        if (isSample) areaUnoccluded += ePerp * cosTheta;
        float visibility = pc.sizeLights.w != 0u ? shadowVisibilitySurface(i, x, n, ng, wi) : 1.0;
        if (visibility <= 0.0) continue;
        vec3 f = evalBrdf(n, wi, wo, albedo, metalRough.x, metalRough.y);
        vec3 l = f * ePerp * (cosTheta * visibility);
        if (isSample)
            areaShadowed += l;
        else
            radiance += l;
    }
    if (pc.areaLights.y > 0u) {
        // Ratio estimator: the samples' shadowed share of the exact unoccluded irradiance. Where
        // no sample is above x's horizon, the part of an emitter that is gets no visibility
        // estimate and counts as visible (Lambertian lobe).
        vec3 exact = emitterIrradiance(x, n);
        for (int ch = 0; ch < 3; ++ch) {
            radiance[ch] += areaUnoccluded[ch] > 0.0
                                ? areaShadowed[ch] * (exact[ch] / areaUnoccluded[ch])
                                : albedo[ch] * (1.0 - metalRough.x) * exact[ch] / BRDF_PI;
        }
    } else {
        radiance += areaShadowed;
    }
    imageStore(outDirect, pixel, vec4(radiance, 1.0));
}
