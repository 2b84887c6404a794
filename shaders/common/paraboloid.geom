#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require
// Hemispherical paraboloid projection of one triangle into the layer of its instance's cluster
// (Heidrich & Seidel 1998; Aranha et al. §III-C: one layered geometry pass for all clusters).
// The triangle is clipped to the front hemisphere (local z >= 0) in 3D before projecting, so the
// pole of the map (directions behind the eye) is never reached; the clipped polygon is then
// split into n x n sub-triangles, n the smallest count that keeps every edge within
// pc.maxEdgeAngle as seen from the eye (at most pc.maxSubdivision): the projection is not linear
// and the rasteriser interpolates linearly, so long edges would bow (docs/vpl.md "Paraboloid
// maps"). Position, depth, normal and texture coordinate are exact per texel (paraboloid.frag).
#include "common/vpl.glsl"
#include "common/paraboloid_pc.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 48) out;

layout(set = 1, binding = 0, std430) readonly buffer Clusters { VplCluster clusters[]; };

layout(location = 0) in vec3 inWorldPos[];
layout(location = 1) flat in uint inTriangle[];
layout(location = 2) flat in uint inLayer[];

layout(location = 0) flat out uint outTriangle;
layout(location = 1) flat out uint outLayer;

struct Corner {
    vec3 local;  // cluster frame, +z = axis
};

Corner mixCorner(Corner a, Corner b, float t) {
    Corner c;
    c.local = mix(a.local, b.local, t);
    return c;
}

void emitCorner(Corner c) {
    float len = length(c.local);
    vec3 d = len > 0.0 ? c.local / len : vec3(0.0, 0.0, 1.0);
    vec2 p = vplParaboloidProject(d);
    gl_Position = vec4(p, clamp(len / pc.far, 0.0, 1.0), 1.0);
    outTriangle = inTriangle[0];
    outLayer = inLayer[0];
    gl_Layer = int(inLayer[0]);
    EmitVertex();
}

float edgeAngle(vec3 a, vec3 b) {
    float la = length(a), lb = length(b);
    if (la <= 0.0 || lb <= 0.0) return VPL_PI;
    return acos(clamp(dot(a, b) / (la * lb), -1.0, 1.0));
}

Corner bary(Corner a, Corner b, Corner c, float u, float v) {
    Corner r;
    float w = 1.0 - u - v;
    r.local = w * a.local + u * b.local + v * c.local;
    return r;
}

// Emits triangle (a, b, c) split n x n: row j is one strip P(0,j) P(0,j+1) P(1,j) ... P(n-j,j)
// with P(i, j) = a + (b - a) i / n + (c - a) j / n; n (n + 2) vertices in all.
void emitSplit(Corner a, Corner b, Corner c) {
    float widest = max(edgeAngle(a.local, b.local),
                       max(edgeAngle(b.local, c.local), edgeAngle(c.local, a.local)));
    uint n = uint(clamp(ceil(widest / max(pc.maxEdgeAngle, 1e-3)), 1.0,
                        float(clamp(pc.maxSubdivision, 1u, 4u))));
    float inv = 1.0 / float(n);
    for (uint j = 0u; j < n; ++j) {
        for (uint i = 0u; i + j < n; ++i) {
            emitCorner(bary(a, b, c, float(i) * inv, float(j) * inv));
            emitCorner(bary(a, b, c, float(i) * inv, float(j + 1u) * inv));
        }
        emitCorner(bary(a, b, c, float(n - j) * inv, float(j) * inv));
        EndPrimitive();
    }
}

void main() {
    VplCluster cluster = clusters[inLayer[0]];
    if (cluster.position.w < 0.5) return;  // inactive cluster: its layer stays empty
    mat3 frame = vplFrame(cluster.normal.xyz);
    Corner v[3];
    for (int k = 0; k < 3; ++k) {
        v[k].local = frame * (inWorldPos[k] - cluster.position.xyz);
    }
    // Sutherland-Hodgman against the plane z = 0 (keep z >= 0): at most 4 corners.
    Corner poly[4];
    int count = 0;
    for (int k = 0; k < 3; ++k) {
        Corner a = v[k], b = v[(k + 1) % 3];
        bool aIn = a.local.z >= 0.0, bIn = b.local.z >= 0.0;
        if (aIn) poly[count++] = a;
        if (aIn != bIn) {
            float t = a.local.z / (a.local.z - b.local.z);
            Corner c = mixCorner(a, b, t);
            c.local.z = 0.0;
            poly[count++] = c;
        }
    }
    if (count < 3) return;
    emitSplit(poly[0], poly[1], poly[2]);
    if (count == 4) emitSplit(poly[0], poly[2], poly[3]);
}
