#version 460
#extension GL_GOOGLE_include_directive : require
// Light-view map (a reflective shadow map reduced to what the photons need), two layers:
//   position  xyz world position of the nearest surface, w = 1
//   normal    xyz unit shading normal on the light's side, as the G-buffer computes it with the
//             light as the viewer (common/gbuffer.frag): the geometric normal is put on the
//             light's side, then the interpolated shading normal on the side of that
// Alpha-masked texels are cut out as in the shadow maps. An emitter sample's own plane is not
// rendered (as in its shadow cube: it cannot occlude the sample's hemisphere).
#define SCENE_IMPLICIT_LOD
#include "common/scene.glsl"
#define LIGHT_VIEW_RASTER
#include "light_view.glsl"

layout(location = 0) in vec3 inWorldPos;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
layout(location = 3) flat in uint inTriangle;

layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;

void main() {
    Material m = fetchMaterial(inTriangle);
    if (alphaCutout(m, inUv)) discard;
    if (pc.skip.x > 0.0 && abs(dot(pc.skipPlane.xyz, inWorldPos) + pc.skipPlane.w) < pc.skip.x) {
        discard;
    }
    vec3 toLight = pc.toLight.w > 0.5 ? pc.toLight.xyz : pc.toLight.xyz - inWorldPos;
    vec3 ng = triangleGeometricNormal(inTriangle);
    vec3 ngLight = dot(ng, toLight) >= 0.0 ? ng : -ng;
    vec3 n = normalize(inNormal);
    if (dot(n, ngLight) < 0.0) n = -n;
    outPosition = vec4(inWorldPos, 1.0);
    outNormal = vec4(n, 1.0);
}
