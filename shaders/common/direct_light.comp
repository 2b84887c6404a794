#version 460
#extension GL_GOOGLE_include_directive : require
// Direct light (core/passes/direct_light.cpp): one thread per pixel,
//   direct.rgb = sum over the pass lights of f(wi, wo) * E_perp * max(0, n.wi) * V
// with wo toward the camera, f from brdf.glsl, E_perp from lights.glsl and V from shadow.glsl.
// No ambient term, no clamping. direct.a = 1 on covered pixels, 0 on the background.
#include "common/brdf.glsl"
#define SHADOW_SET 0
#define SHADOW_BINDING 6
#include "common/shadow.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D gMaterial;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D outDirect;

layout(push_constant, std430) uniform DirectPush {
    vec4 cameraPosition;  // xyz world
    uvec4 sizeLights;     // x width, y height, z light count, w 1 = shadows on
} pc;

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
    vec2 metalRough = imageLoad(gMaterial, pixel).xy;
    vec3 wo = normalize(pc.cameraPosition.xyz - x);

    // Sum f * E * V over the lights
    vec3 radiance = vec3(0.0);
    for (uint i = 0u; i < pc.sizeLights.z; ++i) {
        PassLight light = passLights[i];
        vec3 wi;
        float dist;
        vec3 ePerp = lightIrradiancePerp(light, x, wi, dist);
        float cosTheta = dot(n, wi);
        if (cosTheta <= 0.0 || all(equal(ePerp, vec3(0.0)))) continue;
        float visibility = pc.sizeLights.w != 0u ? shadowVisibility(light, x, n, wi) : 1.0;
        if (visibility <= 0.0) continue;
        vec3 f = evalBrdf(n, wi, wo, albedo, metalRough.x, metalRough.y);
        radiance += f * ePerp * (cosTheta * visibility);
    }
    imageStore(outDirect, pixel, vec4(radiance, 1.0));
}
