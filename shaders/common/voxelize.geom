#version 460
#extension GL_GOOGLE_include_directive : require
// Voxelization, stage 2 (notes 001 §2.2 [C], 003 §2.1): per triangle, the dominant axis of its
// normal picks the orthographic projection (the largest projected area, so no holes), onto an
// N x N viewport (one pixel = one voxel column). Lavapipe has no conservative rasterization, so
// the projected triangle is enlarged: each edge line is pushed out by the half-pixel box's
// semidiagonal and adjacent lines are intersected (Hasselgren et al. 2005, GPU Gems 2 ch. 42),
// which covers the centre of every pixel the triangle touches. The over-coverage at sharp
// corners is removed in the fragment shader (AABB clip, then an exact triangle/voxel test).
#include "common/voxel_pc.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;

layout(location = 0) in vec3 inGrid[];
layout(location = 1) flat in uint inTriangle[];

layout(location = 0) flat out uint outTriangle;
layout(location = 1) flat out uint outAxis;
layout(location = 2) flat out vec3 outP0;  // triangle in projected grid space (u, v, depth)
layout(location = 3) flat out vec3 outP1;
layout(location = 4) flat out vec3 outP2;
layout(location = 5) flat out vec4 outAabb;  // projected (u, v) bounds, not enlarged

// Dominant axis a: (u, v, w) = X: (y, z, x), Y: (z, x, y), Z: (x, y, z).
vec3 swizzleToAxis(vec3 g, uint a) {
    return a == 0u ? g.yzx : (a == 1u ? g.zxy : g);
}

void main() {
    vec3 n = cross(inGrid[1] - inGrid[0], inGrid[2] - inGrid[0]);
    vec3 an = abs(n);
    if (an.x + an.y + an.z == 0.0) return;  // degenerate
    uint axis = (an.z >= an.x && an.z >= an.y) ? 2u : (an.y >= an.x ? 1u : 0u);
    vec3 p[3];
    for (int i = 0; i < 3; ++i)
        p[i] = swizzleToAxis(inGrid[i], axis);

    // Counter-clockwise order in (u, v) for the outward edge normals.
    vec2 a[3] = vec2[3](p[0].xy, p[1].xy, p[2].xy);
    float area = (a[1].x - a[0].x) * (a[2].y - a[0].y) - (a[1].y - a[0].y) * (a[2].x - a[0].x);
    if (area < 0.0) {
        vec2 t = a[1];
        a[1] = a[2];
        a[2] = t;
    }
    // Edge i from a[i] to a[i+1]: line (nx, ny, c), inside where nx*x + ny*y + c <= 0, then
    // moved out by 0.5 * (|nx| + |ny|) (the support of the half-pixel box).
    vec3 lines[3];
    for (int i = 0; i < 3; ++i) {
        vec2 e = a[(i + 1) % 3] - a[i];
        vec2 en = vec2(e.y, -e.x);
        lines[i] = vec3(en, -dot(en, a[i]) - 0.5 * (abs(en.x) + abs(en.y)));
    }
    vec2 lo = min(a[0], min(a[1], a[2])), hi = max(a[0], max(a[1], a[2]));
    float n2 = float(voxelResolution(pc.grid));
    for (int i = 0; i < 3; ++i) {
        vec3 h = cross(lines[(i + 2) % 3], lines[i]);
        vec2 q = abs(h.z) > 1e-12 ? h.xy / h.z : a[i];
        outTriangle = inTriangle[0];
        outAxis = axis;
        outP0 = p[0];
        outP1 = p[1];
        outP2 = p[2];
        outAabb = vec4(lo, hi);
        gl_Position = vec4(q / n2 * 2.0 - 1.0, 0.5, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}
