#version 460
#extension GL_GOOGLE_include_directive : require
// Identification of unique geometry clusters (IUGC; Noël & Biri 2014 §V-B, clustered shading of
// Olsson et al. 2012 with its local sort): one workgroup per T x T screen tile. Every covered
// pixel gets the key (visibility cluster, depth slice), the tile's keys are sorted in shared
// memory (bitonic), each distinct key becomes one geometry cluster (so all its fragments share
// one visibility cluster, the paper's added constraint), numbered globally by one atomic per
// tile, with the world-space box of its pixels. Depth slices are exponential in view depth
// between zNear and zFar (Olsson et al. §4).
#include "topovpl.glsl"

layout(local_size_x = 256) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, r32ui) uniform readonly uimage2D visClusters;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimage2D geoImage;
layout(set = 0, binding = 3, std430) writeonly buffer GeoClusters { TopoGeoCluster geo[]; };
layout(set = 0, binding = 4, std430) buffer State { uint state[]; };  // [0] geometry clusters

layout(push_constant, std430) uniform Push {
    vec4 eye;      // xyz camera position, w zNear
    vec4 forward;  // xyz unit view direction, w zFar
    uint tile;     // T (8, 16 or 32)
    uint slices;   // S
} pc;

const uint kMaxItems = 1024u;
shared uint keys[kMaxItems];
shared uint items[kMaxItems];  // pixel index within the tile
shared uint localId[kMaxItems];
shared uint tileBase;

void main() {
    uint lid = gl_LocalInvocationIndex;
    uint n = pc.tile * pc.tile;
    ivec2 size = imageSize(gPosition);
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * int(pc.tile);
    float logRange = log(max(pc.forward.w / pc.eye.w, 1.0 + 1e-6));
    for (uint i = lid; i < n; i += 256u) {
        ivec2 px = origin + ivec2(i % pc.tile, i / pc.tile);
        uint key = TOPO_NONE;
        if (all(lessThan(px, size))) {
            vec4 p = imageLoad(gPosition, px);
            uint vc = imageLoad(visClusters, px).x;
            if (p.w > 0.5 && vc != TOPO_NONE) {
                float z = max(dot(p.xyz - pc.eye.xyz, pc.forward.xyz), pc.eye.w);
                int s = int(floor(log(z / pc.eye.w) / logRange * float(pc.slices)));
                uint slice = uint(clamp(s, 0, int(pc.slices) - 1));
                key = vc * pc.slices + slice;
            }
        }
        keys[i] = key;
        items[i] = i;
    }
    barrier();
    // Bitonic sort of the n = T^2 keys (a power of two), ascending.
    for (uint k = 2u; k <= n; k <<= 1u) {
        for (uint j = k >> 1u; j > 0u; j >>= 1u) {
            for (uint i = lid; i < n; i += 256u) {
                uint ixj = i ^ j;
                if (ixj > i) {
                    bool ascending = (i & k) == 0u;
                    uint a = keys[i], b = keys[ixj];
                    if ((a > b) == ascending) {
                        keys[i] = b;
                        keys[ixj] = a;
                        uint t = items[i];
                        items[i] = items[ixj];
                        items[ixj] = t;
                    }
                }
            }
            barrier();
        }
    }
    // Number the distinct keys of the tile (a serial scan over at most 1024 sorted keys).
    if (lid == 0u) {
        uint count = 0u;
        for (uint i = 0u; i < n; ++i) {
            if (keys[i] == TOPO_NONE) break;  // invalid keys sort last
            if (i == 0u || keys[i] != keys[i - 1u]) ++count;
            localId[i] = count - 1u;
        }
        tileBase = count > 0u ? atomicAdd(state[0], count) : 0u;
    }
    barrier();
    uint tilesX = (uint(size.x) + pc.tile - 1u) / pc.tile;
    for (uint i = lid; i < n; i += 256u) {
        uint item = items[i];
        ivec2 px = origin + ivec2(item % pc.tile, item / pc.tile);
        if (keys[i] == TOPO_NONE) {
            if (all(lessThan(px, size))) imageStore(geoImage, px, uvec4(TOPO_NONE));
            continue;
        }
        uint g = tileBase + localId[i];
        imageStore(geoImage, px, uvec4(g));
        if (i > 0u && keys[i] == keys[i - 1u]) continue;
        // The head of a run of equal keys: the box of the run's pixels.
        vec3 lo = vec3(3.4e38), hi = vec3(-3.4e38);
        uint count = 0u;
        for (uint j = i; j < n && keys[j] == keys[i]; ++j) {
            uint it = items[j];
            vec3 p = imageLoad(gPosition, origin + ivec2(it % pc.tile, it / pc.tile)).xyz;
            lo = min(lo, p);
            hi = max(hi, p);
            ++count;
        }
        uint tileIndex = gl_WorkGroupID.x + tilesX * gl_WorkGroupID.y;
        geo[g] = TopoGeoCluster(vec4(lo, 0.0), vec4(hi, 0.0),
                                uvec4(keys[i] / pc.slices, count, tileIndex, keys[i] % pc.slices));
    }
}
