// Shared by the per-frame passes of `topovpl` (Noël & Biri 2014 §V; techniques/topovpl/
// gate_lighting.h mirrors the structs, std430; techniques/topovpl/gate_cones.h is the C++ mirror
// of the cone tests that the CPU tests check).
#ifndef GILAB_TOPOVPL_GLSL
#define GILAB_TOPOVPL_GLSL

const uint TOPO_NONE = 0xFFFFFFFFu;

// A visibility gate (§IV-C, E4): a disk between clusters a and b.
struct TopoGate {
    vec4 centreRadius;  // xyz disk centre (world), w radius (after the gate-radius rule)
    vec4 normal;        // xyz unit normal (along the skeleton edge), w unused
    uvec4 clusters;     // x cluster a, y cluster b, zw unused
};

// A geometry cluster of the clustered shading (§V-B, IUGC): the pixels of one tile, one depth
// slice and one visibility cluster, with their world-space bounding box.
struct TopoGeoCluster {
    vec4 lo;      // xyz box minimum (world)
    vec4 hi;      // xyz box maximum
    uvec4 info;   // x visibility cluster, y pixel count, z tile index, w depth slice
};

// (E7) Exact test: is p seen from the VPL at x through the gate disk? The segment x -> p must
// cross the gate's plane strictly between its ends, inside the disk.
bool topoThroughGate(vec3 x, vec3 p, TopoGate g) {
    vec3 n = g.normal.xyz;
    vec3 c = g.centreRadius.xyz;
    float denom = dot(n, p - x);
    float len = length(p - x);
    if (abs(denom) <= 1e-6 * len) return false;  // the segment is parallel to the gate
    float t = dot(n, c - x) / denom;
    if (!(t > 0.0 && t < 1.0)) return false;
    vec3 q = x + t * (p - x) - c;
    return dot(q, q) <= g.centreRadius.w * g.centreRadius.w;
}

// (E8) Conservative test for light assignment: can any point of the sphere (s, rho) be seen
// from x through the gate? The cone from x around the gate's bounding sphere (half-angle
// asin(r / |c - x|)) must reach the sphere, and the sphere must reach past the gate's plane.
bool topoConeHitsSphere(vec3 x, TopoGate g, vec3 s, float rho) {
    vec3 c = g.centreRadius.xyz;
    float r = g.centreRadius.w;
    vec3 farSide = g.normal.xyz * (dot(g.normal.xyz, c - x) >= 0.0 ? 1.0 : -1.0);
    if (dot(farSide, s - c) <= -rho) return false;  // wholly on the VPL's side of the gate
    vec3 toC = c - x;
    float dc = length(toC);
    if (dc <= r) return true;  // the VPL is inside the gate's sphere: the cone is everything
    vec3 toS = s - x;
    float ds = length(toS);
    if (ds <= rho) return true;
    float beta = asin(min(1.0, r / dc));
    float gamma = asin(min(1.0, rho / ds));
    float cosAngle = clamp(dot(toC, toS) / (dc * ds), -1.0, 1.0);
    return acos(cosAngle) <= beta + gamma + 1e-5;
}

#endif  // GILAB_TOPOVPL_GLSL
