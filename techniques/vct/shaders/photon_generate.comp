#version 460
#extension GL_GOOGLE_include_directive : require
// Photon generation (notes 001 §2.5): one photon per light-view texel of one batch of views.
// The flux is what the light sends through the texel, whether or not it hits a surface
// (positionValid.w = 0 for a miss):
//   pinhole (point, spot, emitter sample): Phi = I * lobe(w) * dOmega, w the texel's ray,
//       dOmega = dA * (m . ray) / |ray|^3 with ray on the unit-distance image plane of normal m
//       and dA = (2 |axisX| / W) (2 |axisY| / H) the texel's area on it (= dx dy / (1 + x^2 +
//       y^2)^{3/2} for a centred window)
//   orthographic (directional): Phi = E * texel area, toLight = -direction
// lobe(w) = 1 (point), the glTF spot falloff of common/lights.glsl, or the cosine lobe of an
// emitter sample max(0, n_e . w) (|n_e . w| when double-sided), as the direct pass evaluates it.
// The irradiance at a hit x with shading normal n (light's side, from the light-view raster):
//   pinhole: E = I * lobe(w_x) * max(0, n . l) / r^2 with w_x, l, r the exact direction and
//            distance between the light and x;  orthographic: E = E_perp * max(0, n . l)
// A hit whose surface faces away from the light (n . l <= 0) carries nothing (flux = E = 0);
// normal.w = 1 marks the hits that face the light.
#include "common/lights.glsl"
#include "light_view.glsl"
#include "photon.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2DArray lightViewPositions;
layout(set = 0, binding = 1, rgba16f) uniform readonly image2DArray lightViewNormals;
layout(set = 0, binding = 2, std430) readonly buffer LightViews {
    LightView views[];
};
layout(set = 0, binding = 3, std430) writeonly buffer Photons {
    Photon photons[];
};

layout(push_constant, std430) uniform PhotonPush {
    uvec4 sizes;  // x first view of the batch, y its view count
} pc;

float lobe(LightView view, vec3 dirFromLight) {
    uint kind = uint(view.intensity.w + 0.5);
    if (kind == LIGHT_VIEW_LOBE_SPOT) {
        PassLight light;
        light.direction = vec4(view.spotAxis.xyz, 0.0);
        light.cone = view.cone;
        return spotAttenuation(light, dirFromLight);
    }
    if (kind == LIGHT_VIEW_LOBE_COSINE) return max(dot(view.spotAxis.xyz, dirFromLight), 0.0);
    if (kind == LIGHT_VIEW_LOBE_COSINE_2S) return abs(dot(view.spotAxis.xyz, dirFromLight));
    return 1.0;
}

void main() {
    uvec3 id = gl_GlobalInvocationID;
    if (id.z >= pc.sizes.y) return;
    LightView view = views[pc.sizes.x + id.z];
    uvec2 res = view.texels.xy;
    if (id.x >= res.x || id.y >= res.y) return;
    ivec3 texel = ivec3(id.xy, int(view.texels.w));
    vec4 hit = imageLoad(lightViewPositions, texel);
    vec2 ndc = (vec2(id.xy) + 0.5) / vec2(res) * 2.0 - 1.0;
    float texelArea = (2.0 * view.axisX.w / float(res.x)) * (2.0 * view.axisY.w / float(res.y));
    bool valid = hit.w > 0.5;

    Photon p;
    p.positionValid = valid ? vec4(hit.xyz, 1.0) : vec4(0.0);
    p.normal = vec4(0.0);
    vec3 ePerp = vec3(0.0);  // irradiance on a surface facing the light, at the hit
    vec3 toLight;
    if (view.positionKind.w > 0.5) {
        p.flux = vec4(view.intensity.rgb * texelArea, 0.0);
        toLight = -normalize(view.forward.xyz);
        ePerp = view.intensity.rgb;
    } else {
        vec3 ray = view.forward.xyz + ndc.x * view.axisX.xyz + ndc.y * view.axisY.xyz;
        float len = length(ray);
        vec3 planeNormal = normalize(cross(view.axisX.xyz, view.axisY.xyz));
        float solidAngle = texelArea * abs(dot(planeNormal, ray)) / (len * len * len);
        vec3 dir = ray / len;
        p.flux = vec4(view.intensity.rgb * (solidAngle * lobe(view, dir)), 0.0);
        toLight = -dir;
        if (valid) {
            vec3 d = hit.xyz - view.positionKind.xyz;
            float r2 = dot(d, d);
            if (r2 > 0.0) ePerp = view.intensity.rgb * (lobe(view, d * inversesqrt(r2)) / r2);
        }
    }
    p.toLight = vec4(toLight, 0.0);
    vec3 irradiance = vec3(0.0);
    if (valid) {
        vec3 n = imageLoad(lightViewNormals, texel).xyz;
        n *= inversesqrt(max(dot(n, n), 1e-30));
        p.normal = vec4(n, 0.0);
        vec3 l = view.positionKind.w > 0.5 ? toLight : normalize(view.positionKind.xyz - hit.xyz);
        float cosTheta = dot(n, l);
        if (cosTheta > 0.0) {
            irradiance = ePerp * cosTheta;
            p.normal.w = 1.0;
        } else {
            p.flux = vec4(0.0);  // back-facing: carries nothing
        }
    }
    p.irradiance = vec4(irradiance, float(view.group.x));
    photons[view.texels.z + id.y * res.x + id.x] = p;
}
