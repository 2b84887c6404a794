#version 460
// Test shader: looks scene data up through common/scene.glsl for a list of queries.
#extension GL_GOOGLE_include_directive : require
#include "common/scene.glsl"

layout(local_size_x = 64) in;
struct Query { uint triangle; float u; float v; float lod; };  // u, v = uv or barycentrics
layout(set = 1, binding = 0, scalar) readonly buffer Queries { Query queries[]; };
layout(set = 1, binding = 1, scalar) writeonly buffer Results { vec4 results[]; };  // 6 per query

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(queries.length())) return;
    Query q = queries[i];
    Material m = fetchMaterial(q.triangle);
    vec2 uv = vec2(q.u, q.v);
    results[6 * i + 0] = m.baseColor;
    results[6 * i + 1] = q.lod > 0.0 ? sampleBaseColorLod(m, uv, q.lod) : sampleBaseColor(m, uv);
    results[6 * i + 2] = vec4(sampleEmission(m, uv), float(m.flags));
    results[6 * i + 3] = vec4(sampleMetalRough(m, uv), alphaCutout(m, uv) ? 1.0 : 0.0,
                              float(sceneLightCount()));
    SceneVertex v = interpolateVertex(q.triangle, uv);
    results[6 * i + 4] = vec4(v.position, v.uv.x);
    results[6 * i + 5] = vec4(v.normal, float(sceneTriangleCount()));
}
