#version 460
// Batch ray queries on the GPU ray tracer (core/rt/ray_query.h): one thread per ray, closest
// hit (mode 0) or occlusion (mode 1). Used by `gilab bench rt` and its tests to validate
// rt_trace.glsl against Embree.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 64) in;

#define RT_SET 0
#define RT_BINDING 2
#include "rt_trace.glsl"

struct QueryRay {
    vec3 origin;
    float tMin;
    vec3 direction;
    float tMax;
};
struct QueryHit {
    float t;         // closest: hit distance (in units of direction); occlusion: 1 = occluded
    uint triangle;   // 0xffffffff = miss
    vec2 bary;
};

layout(set = 0, binding = 0, scalar) readonly buffer Rays { QueryRay rays[]; };
layout(set = 0, binding = 1, scalar) writeonly buffer Hits { QueryHit hits[]; };

layout(push_constant) uniform Push {
    uint count;
    uint mode;
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    QueryRay r = rays[i];
    QueryHit h;
    if (pc.mode == 1u) {
        bool occluded = rtOccluded(r.origin, r.direction, r.tMin, r.tMax);
        h.t = occluded ? 1.0 : 0.0;
        h.triangle = 0xffffffffu;
        h.bary = vec2(0.0);
    } else {
        RtHit hit;
        bool found = rtClosest(r.origin, r.direction, r.tMin, r.tMax, hit);
        h.t = found ? hit.t : -1.0;
        h.triangle = found ? hit.triangle : 0xffffffffu;
        h.bary = hit.bary;
    }
    hits[i] = h;
}
