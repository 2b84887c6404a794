#version 460
#extension GL_GOOGLE_include_directive : require
// Writes the linear distance from the light (shadow.glsl explains both kinds). Alpha-masked
// texels are cut out. For an emitter sample, surfaces in the emitter's own plane are skipped:
// a segment from a point of that plane to a point off it cannot be blocked by the plane.
#define SCENE_IMPLICIT_LOD
#include "common/scene.glsl"
#include "common/shadow_pc.glsl"

layout(location = 0) in vec3 inWorldPos;
layout(location = 1) in vec2 inUv;
layout(location = 2) flat in uint inTriangle;

layout(location = 0) out float outDistance;

void main() {
    Material m = fetchMaterial(inTriangle);
    if (alphaCutout(m, inUv)) discard;
    if (pc.params.x > 0.0 && abs(dot(pc.skipPlane.xyz, inWorldPos) - pc.skipPlane.w) <= pc.params.x) {
        discard;
    }
    outDistance = pc.origin.w > 0.5 ? dot(inWorldPos - pc.origin.xyz, pc.direction.xyz)
                                    : length(inWorldPos - pc.origin.xyz);
}
