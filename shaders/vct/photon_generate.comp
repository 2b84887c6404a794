#version 460
#extension GL_GOOGLE_include_directive : require
// Photon generation (notes 001 §2.5): one photon per light-view texel. The flux is what the light
// sends through the texel, whether or not it hits a surface (positionValid.w = 0 for a miss):
//   pinhole (point, spot):  Phi = I * s(omega) * dOmega,
//                           dOmega = dx dy / (1 + x^2 + y^2)^{3/2}, (x, y) the texel centre on
//                           the image plane at unit distance, dx = dy = 2 tan(fov/2) / res
//   orthographic (directional): Phi = E * texel area, toLight = -direction
// s(omega) is the glTF spot falloff of common/lights.glsl (1 for point lights).
#include "common/lights.glsl"
#include "vct/light_view.glsl"
#include "vct/photon.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2DArray lightViewPositions;
layout(set = 0, binding = 1, std430) readonly buffer LightViews {
    LightView views[];
};
layout(set = 0, binding = 2, std430) writeonly buffer Photons {
    Photon photons[];
};

layout(push_constant, std430) uniform PhotonPush {
    uvec4 sizes;  // x map resolution, y layer count
} pc;

void main() {
    uint res = pc.sizes.x;
    uvec3 id = gl_GlobalInvocationID;
    if (id.x >= res || id.y >= res || id.z >= pc.sizes.y) return;
    LightView view = views[id.z];
    vec4 hit = imageLoad(lightViewPositions, ivec3(id));
    vec2 ndc = (vec2(id.xy) + 0.5) / float(res) * 2.0 - 1.0;

    Photon p;
    p.positionValid = hit.w > 0.5 ? vec4(hit.xyz, 1.0) : vec4(0.0);
    if (view.positionKind.w > 0.5) {
        float texel = 2.0 * view.axisX.w / float(res);
        p.flux = vec4(view.intensity.rgb * (texel * texel), 0.0);
        p.toLight = vec4(-normalize(view.forward.xyz), 0.0);
    } else {
        float tanHalf = view.axisX.w;
        vec2 xy = ndc * tanHalf;
        float dx = 2.0 * tanHalf / float(res);
        float q = 1.0 + dot(xy, xy);
        float solidAngle = dx * dx / (q * sqrt(q));
        vec3 ray = normalize(view.forward.xyz + ndc.x * view.axisX.xyz + ndc.y * view.axisY.xyz);
        float falloff = 1.0;
        if (view.spotAxis.w > 0.5) {
            PassLight light;
            light.direction = vec4(view.spotAxis.xyz, 0.0);
            light.cone = view.cone;
            falloff = spotAttenuation(light, ray);
        }
        p.flux = vec4(view.intensity.rgb * (solidAngle * falloff), 0.0);
        p.toLight = vec4(-ray, 0.0);
    }
    photons[(id.z * res + id.y) * res + id.x] = p;
}
