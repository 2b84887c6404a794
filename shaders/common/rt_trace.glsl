// The GPU ray tracer (core/rt/bvh.h, core/rt/gpu_bvh.h): stack traversal of the flattened
// binary BVH with closest-hit and any-hit queries, in compute shaders (lavapipe has no
// ray-tracing extensions). Back faces are not culled. Validated against Embree by
// `gilab bench rt` (docs/gpu_rays.md).
//
// Define before including (after #version and GL_GOOGLE_include_directive):
//   RT_SET      descriptor set of the two buffers
//   RT_BINDING  binding of the nodes; the triangles are RT_BINDING + 1
// A hit reports the scene triangle id and Embree's barycentrics (b1, b2), p = v0 + b1 e1 + b2 e2,
// so interpolateVertex(hit.triangle, hit.bary) (scene.glsl) gives its position, normal and uv.
#ifndef GILAB_RT_TRACE_GLSL
#define GILAB_RT_TRACE_GLSL

#extension GL_EXT_scalar_block_layout : require

#define RT_STACK_SIZE 64

struct RtNode {
    vec3 lower;
    uint rightOrFirst;  // interior: right child; leaf: first triangle
    vec3 upper;
    uint count;         // 0 = interior (left child = next node), else triangles in the leaf
};

struct RtTriangle {
    vec3 v0;
    uint triangle;  // scene triangle id
    vec3 e1;
    float pad1;
    vec3 e2;
    float pad2;
};

struct RtHit {
    float t;
    uint triangle;
    vec2 bary;  // (b1, b2)
};

layout(set = RT_SET, binding = RT_BINDING, scalar) readonly buffer RtNodes {
    RtNode rtNodes[];
};
layout(set = RT_SET, binding = RT_BINDING + 1, scalar) readonly buffer RtTriangles {
    RtTriangle rtTriangles[];
};

// Entry and exit distances of the ray through a node's box (entry > exit: missed).
vec2 rtSlabs(vec3 lower, vec3 upper, vec3 o, vec3 invD) {
    vec3 t0 = (lower - o) * invD;
    vec3 t1 = (upper - o) * invD;
    vec3 tn = min(t0, t1);
    vec3 tf = max(t0, t1);
    return vec2(max(max(tn.x, tn.y), tn.z), min(min(tf.x, tf.y), tf.z));
}

// Moller-Trumbore, both faces: t of o + t d in [tMin, tMax] and the barycentrics, else -1.
float rtIntersectTriangle(RtTriangle tri, vec3 o, vec3 d, float tMin, float tMax, out vec2 bary) {
    vec3 p = cross(d, tri.e2);
    float det = dot(tri.e1, p);
    bary = vec2(0.0);
    if (det == 0.0) return -1.0;
    float inv = 1.0 / det;
    vec3 s = o - tri.v0;
    float b1 = dot(s, p) * inv;
    if (b1 < 0.0 || b1 > 1.0) return -1.0;
    vec3 q = cross(s, tri.e1);
    float b2 = dot(d, q) * inv;
    if (b2 < 0.0 || b1 + b2 > 1.0) return -1.0;
    float t = dot(tri.e2, q) * inv;
    if (t < tMin || t > tMax) return -1.0;
    bary = vec2(b1, b2);
    return t;
}

// 1 / d with zero components replaced by a huge finite value of the same sign (no 0 * inf).
vec3 rtSafeInverse(vec3 d) {
    const float big = 1.0e30;
    return vec3(abs(d.x) > 1.0e-30 ? 1.0 / d.x : (d.x < 0.0 ? -big : big),
                abs(d.y) > 1.0e-30 ? 1.0 / d.y : (d.y < 0.0 ? -big : big),
                abs(d.z) > 1.0e-30 ? 1.0 / d.z : (d.z < 0.0 ? -big : big));
}

// Closest hit of o + t d with t in [tMin, tMax] (d need not be unit; t is in units of d).
bool rtClosest(vec3 o, vec3 d, float tMin, float tMax, out RtHit hit) {
    hit.t = tMax;
    hit.triangle = 0xffffffffu;
    hit.bary = vec2(0.0);
    vec3 invD = rtSafeInverse(d);
    uint stack[RT_STACK_SIZE];
    int top = 0;
    uint node = 0u;
    while (true) {
        RtNode n = rtNodes[node];
        vec2 slab = rtSlabs(n.lower, n.upper, o, invD);
        bool enter = slab.x <= slab.y && slab.y >= tMin && slab.x <= hit.t;
        if (enter && n.count > 0u) {
            for (uint i = 0u; i < n.count; ++i) {
                RtTriangle tri = rtTriangles[n.rightOrFirst + i];
                vec2 bary;
                float t = rtIntersectTriangle(tri, o, d, tMin, hit.t, bary);
                // Ties (coplanar duplicates): the lower triangle id wins, as a stable rule
                if (t >= 0.0 && (t < hit.t || (t == hit.t && tri.triangle < hit.triangle))) {
                    hit.t = t;
                    hit.triangle = tri.triangle;
                    hit.bary = bary;
                }
            }
        } else if (enter) {
            // Interior: visit the nearer child first, push the other
            uint left = node + 1u, right = n.rightOrFirst;
            RtNode l = rtNodes[left], r = rtNodes[right];
            float tl = rtSlabs(l.lower, l.upper, o, invD).x;
            float tr = rtSlabs(r.lower, r.upper, o, invD).x;
            uint nearChild = tl <= tr ? left : right;
            uint farChild = tl <= tr ? right : left;
            if (top < RT_STACK_SIZE) stack[top++] = farChild;
            node = nearChild;
            continue;
        }
        if (top == 0) break;
        node = stack[--top];
    }
    return hit.triangle != 0xffffffffu;
}

// Whether anything lies on o + t d with t in [tMin, tMax] (shadow rays; stops at the first hit).
bool rtOccluded(vec3 o, vec3 d, float tMin, float tMax) {
    vec3 invD = rtSafeInverse(d);
    uint stack[RT_STACK_SIZE];
    int top = 0;
    uint node = 0u;
    while (true) {
        RtNode n = rtNodes[node];
        vec2 slab = rtSlabs(n.lower, n.upper, o, invD);
        bool enter = slab.x <= slab.y && slab.y >= tMin && slab.x <= tMax;
        if (enter && n.count > 0u) {
            for (uint i = 0u; i < n.count; ++i) {
                vec2 bary;
                if (rtIntersectTriangle(rtTriangles[n.rightOrFirst + i], o, d, tMin, tMax,
                                        bary) >= 0.0)
                    return true;
            }
        } else if (enter) {
            if (top < RT_STACK_SIZE) stack[top++] = n.rightOrFirst;
            node = node + 1u;
            continue;
        }
        if (top == 0) break;
        node = stack[--top];
    }
    return false;
}

#endif  // GILAB_RT_TRACE_GLSL
