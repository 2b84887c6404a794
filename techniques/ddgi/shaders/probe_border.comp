#version 460
// ddgi "probe_border" (paper 1 Fig. 3; SDK UpdateBorderTexel): fills each tile's 1-texel
// gutter from the interior with the octahedral wrap, so bilinear lookups are seamless:
// a row-border texel copies the interior texel mirrored in x, a column-border texel the one
// mirrored in y, a corner the diagonally opposite interior corner.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#define DDGI_ATLAS_WRITABLE
#include "ddgi_common.glsl"

layout(push_constant) uniform Push {
    uint distance;  // 0 irradiance, 1 distance
} pc;

void main() {
    bool isDistance = pc.distance != 0u;
    int n = int(isDistance ? ddgi.texels.y : ddgi.texels.x);
    int tile = n + 2;
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    int tilesX = int(ddgi.counts.x * ddgi.counts.y);
    if (texel.x >= tilesX * tile || texel.y >= int(ddgi.counts.z) * tile) return;
    ivec2 p = texel % tile;
    ivec2 origin = texel - p;
    bool borderX = p.x == 0 || p.x == tile - 1;
    bool borderY = p.y == 0 || p.y == tile - 1;
    if (!borderX && !borderY) return;
    ivec2 src;
    if (borderX && borderY) {
        src = ivec2(p.x == 0 ? n : 1, p.y == 0 ? n : 1);
    } else if (borderY) {
        src = ivec2(tile - 1 - p.x, p.y == 0 ? 1 : n);
    } else {
        src = ivec2(p.x == 0 ? 1 : n, tile - 1 - p.y);
    }
    if (isDistance)
        imageStore(distanceAtlas, texel, imageLoad(distanceAtlas, origin + src));
    else
        imageStore(irradianceAtlas, texel, imageLoad(irradianceAtlas, origin + src));
}
