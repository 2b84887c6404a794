#version 460
#extension GL_GOOGLE_include_directive : require
// Reflective shadow map (Dachsbacher & Stamminger 2005, as Aranha et al. §III-A store it: position,
// normal and albedo, not flux; the flux is computed where VPLs are drawn, rsm_vpls.comp):
//   position  xyz world position, w = 1
//   normal    xyz unit shading normal on the light's side (the G-buffer rule with the light as
//             the viewer), w = 1
//   albedo    rgb base colour x texture (linear), w = 1
// Alpha-masked texels are cut out as in the shadow maps; texels with no surface stay 0.
#define SCENE_IMPLICIT_LOD
#include "common/scene.glsl"
#include "common/rsm_pc.glsl"

layout(location = 0) in vec3 inWorldPos;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
layout(location = 3) flat in uint inTriangle;

layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;
layout(location = 2) out vec4 outAlbedo;

void main() {
    Material m = fetchMaterial(inTriangle);
    vec4 baseColor = sampleBaseColor(m, inUv);
    if ((m.flags & MATERIAL_ALPHA_MASK) != 0u && baseColor.a < m.alphaCutoff) discard;
    vec3 toLight = pc.toLight.w > 0.5 ? pc.toLight.xyz : pc.toLight.xyz - inWorldPos;
    vec3 ng = triangleGeometricNormal(inTriangle);
    vec3 ngLight = dot(ng, toLight) >= 0.0 ? ng : -ng;
    vec3 n = normalize(inNormal);
    if (!(dot(n, ngLight) >= 0.0)) n = -n;
    if (any(isnan(n))) n = ngLight;
    outPosition = vec4(inWorldPos, 1.0);
    outNormal = vec4(n, 1.0);
    outAlbedo = vec4(baseColor.rgb, 1.0);
}
