#version 460
#extension GL_GOOGLE_include_directive : require
// Layered paraboloid maps (core/vpl/paraboloid_maps.h): instance i draws the scene into layer i.
#include "common/scene.glsl"

layout(location = 0) out vec3 outWorldPos;
layout(location = 1) flat out uint outTriangle;
layout(location = 2) flat out uint outLayer;

void main() {
    SceneVertex v = fetchVertex(sceneIndices[gl_VertexIndex]);
    outWorldPos = v.position;
    outTriangle = uint(gl_VertexIndex) / 3u;
    outLayer = uint(gl_InstanceIndex);
    gl_Position = vec4(v.position, 1.0);
}
