#version 460
// Test shader: pulls the scene's vertices through scene.glsl and maps uv [0,1]^2 to the screen.
#extension GL_GOOGLE_include_directive : require
#include "common/scene.glsl"
layout(location = 0) out vec2 outUv;
layout(location = 1) flat out uint outTriangle;
void main() {
    SceneVertex v = fetchVertex(sceneIndices[gl_VertexIndex]);
    outUv = v.uv;
    outTriangle = uint(gl_VertexIndex) / 3u;
    gl_Position = vec4(v.uv * 2.0 - 1.0, 0.5, 1.0);
}
