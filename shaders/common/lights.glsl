// The pass light table: every light the rasteriser shades with (the scene's punctual lights,
// then the emitter samples that stand in for emissive triangles), each with its shadow map.
// Mirrored by gilab::PassLight in core/passes/pass_light.h. Units: docs/shared_passes.md.
#ifndef GILAB_LIGHTS_GLSL
#define GILAB_LIGHTS_GLSL

#define PASS_LIGHT_POINT 0
#define PASS_LIGHT_SPOT 1
#define PASS_LIGHT_DIRECTIONAL 2
#define PASS_LIGHT_EMITTER_SAMPLE 3

// Shadow map kinds (PassLight.shadow.x).
#define SHADOW_NONE 0
#define SHADOW_MAP_2D 1
#define SHADOW_CUBE 2
#define SHADOW_AREA_CUBE 3

struct PassLight {
    vec4 positionType;  // xyz position (not directional), w = PASS_LIGHT_*
    vec4 direction;     // xyz: travel direction (spot, directional) or emitter normal (sample);
                        // w: 1 = two-sided emitter sample
    vec4 intensity;     // rgb: W/sr (point, spot), W/m^2 (directional), Le * area (sample);
                        // w: sample area / pi (the squared radius of its disk)
    vec4 cone;          // x cos(inner), y cos(outer) (spot)
    vec4 shadow;        // x SHADOW_* kind, y layer (2D) or cube index, z texel size factor,
                        // w 1 = orthographic (texel size = z) else perspective (z * distance)
    vec4 bias;          // volume receivers (shadowVisibility): x constant, y slope (texels),
                        // z normal offset (texels), w PCF radius
    vec4 surfaceBias;   // surface receivers (shadowVisibilitySurface), the same four settings
    vec4 cascades;      // x first cascade entry, y cascade count (directional lights),
                        // z 1 = receiver-plane test for surface receivers
    vec4 origin;        // orthographic: xyz point on the entry plane (distance = dot(p - o, dir))
    mat4 viewProj;      // 2D maps: world -> Vulkan clip space (y down)
};

// glTF KHR_lights_punctual spot falloff: t = saturate((cd - cosOuter) / (cosInner - cosOuter)),
// attenuation = t^2; equal cones give a hard edge.
float spotAttenuation(PassLight light, vec3 fromLight) {
    float cd = dot(light.direction.xyz, fromLight);
    float cosInner = light.cone.x;
    float cosOuter = light.cone.y;
    if (cosInner - cosOuter <= 0.0) return cd > cosOuter ? 1.0 : 0.0;
    float t = clamp((cd - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
    return t * t;
}

// Irradiance at x on a surface facing the light (before the receiver's cosine), the unit
// direction wi toward the light and the distance to it (1e30 for directional lights).
//   point:       E_perp = I / r^2
//   spot:        E_perp = I * spotAttenuation / r^2
//   directional: E_perp = E
//   sample:      E_perp = Le * A_k * cos(theta_emitter) / (r^2 + A_k / pi)
//                (a disk of area A_k: exact on its axis, bounded by pi * Le as r -> 0, and the
//                cosine-lobe point law E = I cos / r^2 once r is well above the disk's radius)
// The irradiance on a receiver with normal n is E_perp * max(0, dot(n, wi)).
vec3 lightIrradiancePerp(PassLight light, vec3 x, out vec3 wi, out float dist) {
    uint type = uint(light.positionType.w);
    if (type == PASS_LIGHT_DIRECTIONAL) {
        wi = -light.direction.xyz;
        dist = 1.0e30;
        return light.intensity.rgb;
    }
    vec3 d = light.positionType.xyz - x;
    float r2 = dot(d, d);
    if (r2 <= 0.0) {
        wi = vec3(0.0, 1.0, 0.0);
        dist = 0.0;
        return vec3(0.0);
    }
    dist = sqrt(r2);
    wi = d / dist;
    vec3 e = light.intensity.rgb / r2;
    if (type == PASS_LIGHT_SPOT) {
        e *= spotAttenuation(light, -wi);
    } else if (type == PASS_LIGHT_EMITTER_SAMPLE) {
        float cosEmit = dot(light.direction.xyz, -wi);
        cosEmit = light.direction.w > 0.5 ? abs(cosEmit) : max(cosEmit, 0.0);
        e = light.intensity.rgb * (cosEmit / (r2 + light.intensity.w));
    }
    return e;
}

#endif  // GILAB_LIGHTS_GLSL
