#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require
// One texel of a cluster's paraboloid map (core/vpl/paraboloid_maps.h). The texel's direction
// (the inverse paraboloid mapping of its centre) is intersected with the triangle's plane, so
// the stored position, the radial distance (depth) and, through the barycentrics of that point,
// the normal and texture coordinate are exact, whatever the rasteriser interpolated. Layers:
//   position  xyz world position, w radial distance from the eye (0: no surface)
//   normal    xyz unit shading normal on the eye's side, w 1
//   albedo    rgb base colour x texture (linear), w 1
// Texels outside the unit disk, and alpha-masked texels, are not written.
#include "common/scene.glsl"
#include "common/vpl.glsl"
#include "common/paraboloid_pc.glsl"

layout(set = 1, binding = 0, std430) readonly buffer Clusters { VplCluster clusters[]; };

layout(location = 0) flat in uint inTriangle;
layout(location = 1) flat in uint inLayer;

layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;
layout(location = 2) out vec4 outAlbedo;

void main() {
    vec2 p = gl_FragCoord.xy / float(pc.resolution) * 2.0 - 1.0;
    if (dot(p, p) > 1.0) discard;
    VplCluster cluster = clusters[inLayer];
    vec3 eye = cluster.position.xyz;
    vec3 w = transpose(vplFrame(cluster.normal.xyz)) * vplParaboloidDirection(p);

    uvec3 t = fetchTriangle(inTriangle);
    vec3 p0 = fetchVertex(t.x).position, p1 = fetchVertex(t.y).position;
    vec3 p2 = fetchVertex(t.z).position;
    vec3 e1 = p1 - p0, e2 = p2 - p0;
    vec3 ng = cross(e1, e2);
    float denom = dot(ng, w);
    float dist = dot(ng, p0 - eye) / denom;
    if (!(dist > 0.0) || isinf(dist)) discard;  // edge-on or behind: nothing to store
    vec3 x = eye + dist * w;

    // Barycentrics of x. The rasterised coverage has straight edges where the true projection
    // bows: texels just outside the triangle keep the plane point (exact for a coplanar
    // neighbour, e.g. the other half of a quad), texels far outside are not the triangle's
    // (left to the others: a hole rather than a false occluder; docs/vpl.md).
    float d00 = dot(e1, e1), d01 = dot(e1, e2), d11 = dot(e2, e2);
    vec3 q = x - p0;
    float d20 = dot(q, e1), d21 = dot(q, e2);
    float det = d00 * d11 - d01 * d01;
    if (!(det > 0.0)) discard;
    vec2 b = vec2(d11 * d20 - d01 * d21, d00 * d21 - d01 * d20) / det;
    const float slack = 0.02;
    if (b.x < -slack || b.y < -slack || b.x + b.y > 1.0 + slack) discard;
    b = clamp(b, 0.0, 1.0);
    if (b.x + b.y > 1.0) b /= b.x + b.y;
    SceneVertex v = interpolateVertex(inTriangle, b);

    Material m = fetchMaterial(inTriangle);
    vec4 baseColor = sampleBaseColorLod(m, v.uv, 0.0);
    if ((m.flags & MATERIAL_ALPHA_MASK) != 0u && baseColor.a < m.alphaCutoff) discard;

    vec3 ngEye = dot(ng, eye - x) >= 0.0 ? ng : -ng;
    vec3 n = v.normal;
    if (!(dot(n, ngEye) >= 0.0)) n = -n;
    if (any(isnan(n))) n = normalize(ngEye);
    gl_FragDepth = clamp(dist / pc.far, 0.0, 1.0);
    outPosition = vec4(x, dist);
    outNormal = vec4(n, 1.0);
    outAlbedo = vec4(baseColor.rgb, 1.0);
}
