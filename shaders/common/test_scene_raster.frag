#version 460
// Test shader: compiles scene.glsl with SCENE_IMPLICIT_LOD (derivative-based mips).
#extension GL_GOOGLE_include_directive : require
#define SCENE_IMPLICIT_LOD
#include "common/scene.glsl"
layout(location = 0) in vec2 inUv;
layout(location = 1) flat in uint inTriangle;
layout(location = 0) out vec4 outColor;
void main() {
    Material m = fetchMaterial(inTriangle);
    if (alphaCutout(m, inUv)) discard;
    outColor = sampleBaseColor(m, inUv) + vec4(sampleEmission(m, inUv), 0.0);
}
