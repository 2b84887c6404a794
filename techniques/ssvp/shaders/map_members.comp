#version 460
#extension GL_GOOGLE_include_directive : require
// Does a cluster's paraboloid map see its own members? (issue 29; ours, not in the paper.)
// Clustered visibility shades receiver x from VPL i as if from the map's eye, so a member the eye
// does not see is a VPL whose light the gather places wrongly. Per clustered VPL i (global
// index), after the maps: members[i] = (flux, seen by its own map, seen after the move, moved). With
// map_members = reassign, a member its map does not see joins the active cluster whose map sees
// it with the nearest eye (none: it stays); cluster_flux.comp then re-sums the clusters' flux.
#include "kmeans_common.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 3, rgba32f) uniform readonly image2DArray mapPosition;
layout(set = 0, binding = 6, std430) writeonly buffer Members { vec4 members[]; };
#include "common/vpl_visibility.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    uint vi = vplAt(i);
    Vpl v = vpls[vi];
    int own = int(v.normal.w);
    if (!vplValid(i) || own < 0) {
        members[vi] = vec4(0.0);
        return;
    }
    float flux = dot(v.flux.rgb, vec3(1.0 / 3.0));
    // The member is tested lifted along its normal by twice the eye offset: a member on the
    // plane its eye floats over lies on the map's horizon, outside every map, although nothing
    // hides it (and a VPL lights nothing in its own plane).
    vec3 p = v.position.xyz + v.normal.xyz * (2.0 * pc.eyeOffset);
    float seen = vplMapVisible(p, v.normal.xyz, own, pc.mapResolution, pc.biasTexels);
    int chosen = own;
    if (seen == 0.0 && pc.reassign != 0u) {
        float best = 3.0e38;
        for (uint j = 0u; j < pc.clusterCount; ++j) {
            uint c = clusterAt(j);
            if (int(c) == own || clusters[c].position.w < 0.5) continue;
            vec3 d = v.position.xyz - clusters[c].position.xyz;
            if (dot(d, d) >= best) continue;
            if (vplMapVisible(p, v.normal.xyz, int(c), pc.mapResolution, pc.biasTexels) == 0.0)
                continue;
            best = dot(d, d);
            chosen = int(c);
        }
        vpls[vi].normal.w = float(chosen);
    }
    members[vi] = vec4(flux, seen, chosen != own ? 1.0 : seen, chosen != own ? 1.0 : 0.0);
}
