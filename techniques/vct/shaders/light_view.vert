#version 460
#extension GL_GOOGLE_include_directive : require
// Light-view map rasterisation (vct light injection, notes 001 §2.5): the scene pulled from the
// scene set like common/shadow.vert, one map layer per draw.
#include "common/scene.glsl"
#define LIGHT_VIEW_RASTER
#include "light_view.glsl"

layout(location = 0) out vec3 outWorldPos;
layout(location = 1) out vec3 outNormal;
layout(location = 2) out vec2 outUv;
layout(location = 3) flat out uint outTriangle;

void main() {
    SceneVertex v = fetchVertex(sceneIndices[gl_VertexIndex]);
    outWorldPos = v.position;
    outNormal = v.normal;
    outUv = v.uv;
    outTriangle = uint(gl_VertexIndex) / 3u;
    gl_Position = pc.viewProj * vec4(v.position, 1.0);
}
