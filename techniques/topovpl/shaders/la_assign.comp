#version 460
#extension GL_GOOGLE_include_directive : require
// Light assignment (LA; Noël & Biri 2014 §V-C): brute force, one workgroup per geometry cluster
// k, its threads over the VPLs. For VPL i in visibility cluster C_i and the cluster's visibility
// cluster C_g:
//   C_i == C_g                  one entry (i, none): same cluster, no test (quasi-convexity)
//   else, for every gate of C_i whose cone from the VPL reaches the sphere around k's box
//   (conservative test E8)      one entry (i, gate)
//   otherwise                   culled
// Run twice: pass 0 counts each cluster's entries, pass 1 (after la_scan) writes them at the
// cluster's offset, each VPL's entries consecutive, VPLs in index order (deterministic). The
// entry buffer has a fixed capacity: entries beyond it are not written; the host compares the
// total (state[1], from la_scan) with the capacity and reports the overflow.
// Options: unshadowed (every valid VPL, no test: Table II's "no shadows on indirect"), same
// cluster only (no gate lighting), far side only (a gate lights only its other cluster).
#include "common/vpl.glsl"
#include "topovpl.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer Vpls { Vpl vpls[]; };
layout(set = 0, binding = 1, std430) readonly buffer VplClusters { uint vplCluster[]; };
layout(set = 0, binding = 2, std430) readonly buffer Gates { TopoGate gates[]; };
// clusterGates[clusterGateStart[c] .. clusterGateStart[c + 1]): the gates of cluster c.
layout(set = 0, binding = 3, std430) readonly buffer ClusterGateStart { uint clusterGateStart[]; };
layout(set = 0, binding = 4, std430) readonly buffer ClusterGates { uint clusterGates[]; };
layout(set = 0, binding = 5, std430) readonly buffer GeoClusters { TopoGeoCluster geo[]; };
layout(set = 0, binding = 6, std430) buffer Counts { uint counts[]; };
layout(set = 0, binding = 7, std430) readonly buffer Offsets { uint offsets[]; };
layout(set = 0, binding = 8, std430) writeonly buffer Entries { uvec2 entries[]; };
layout(set = 0, binding = 9, std430) readonly buffer State { uint state[]; };

layout(push_constant, std430) uniform Push {
    uint vplCount;
    uint fill;        // 0 count, 1 write
    uint mode;        // 0 gates (the method), 1 same cluster only, 2 unshadowed
    uint farOnly;     // 1: a gate lights only the cluster on its other side
    uint capacity;    // entries
    uint clusterCount;  // visibility clusters (gate lists)
} pc;

shared uint scan[64];

uint addSat(uint a, uint b) { return a + b < a ? 0xFFFFFFFFu : a + b; }

void store(uint at, uvec2 entry) {
    if (at < pc.capacity) entries[at] = entry;
}

// Entries of VPL i for the geometry cluster (visibility cluster vc, sphere s, rho); with
// `write`, stored from `at` on.
uint assign(uint i, uint vc, vec3 s, float rho, bool write, uint at) {
    uint ci = vplCluster[i];
    if (ci == TOPO_NONE || ci >= pc.clusterCount) return 0u;
    if (pc.mode == 2u || ci == vc) {
        if (write) store(at, uvec2(i, TOPO_NONE));
        return 1u;
    }
    if (pc.mode == 1u) return 0u;
    vec3 x = vpls[i].position.xyz;
    uint n = 0u;
    for (uint k = clusterGateStart[ci]; k < clusterGateStart[ci + 1u]; ++k) {
        uint gi = clusterGates[k];
        TopoGate g = gates[gi];
        if (pc.farOnly != 0u) {
            uint other = g.clusters.x == ci ? g.clusters.y : g.clusters.x;
            if (other != vc) continue;
        }
        if (!topoConeHitsSphere(x, g, s, rho)) continue;
        if (write) store(addSat(at, n), uvec2(i, gi));
        ++n;
    }
    return n;
}

void main() {
    uint k = gl_WorkGroupID.x + 32768u * gl_WorkGroupID.y;
    if (k >= state[0]) return;  // uniform per workgroup
    uint lid = gl_LocalInvocationIndex;
    TopoGeoCluster c = geo[k];
    vec3 s = 0.5 * (c.lo.xyz + c.hi.xyz);
    float rho = 0.5 * length(c.hi.xyz - c.lo.xyz);
    uint vc = c.info.x;
    bool write = pc.fill != 0u;
    uint running = write ? offsets[k] : 0u;
    for (uint base = 0u; base < pc.vplCount; base += 64u) {
        uint i = base + lid;
        bool valid = i < pc.vplCount && vpls[i].position.w > 0.5;
        uint mine = valid ? assign(i, vc, s, rho, false, 0u) : 0u;
        // Inclusive scan of the 64 counts (Hillis-Steele).
        scan[lid] = mine;
        barrier();
        for (uint d = 1u; d < 64u; d <<= 1u) {
            uint add = lid >= d ? scan[lid - d] : 0u;
            barrier();
            scan[lid] += add;
            barrier();
        }
        uint total = scan[63];
        if (write && mine > 0u) assign(i, vc, s, rho, true, addSat(running, scan[lid] - mine));
        running = addSat(running, total);
        barrier();
    }
    if (!write && lid == 0u) counts[k] = running;
}
