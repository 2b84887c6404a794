#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require
// First-bounce VPLs from a reflective shadow map (core/vpl/rsm.h; Aranha et al. §III-A): VPL k of
// n reads the RSM texel under the fixed 2D Hammersley point k (Eq. 1), the same every frame,
// toroidally shifted by the technique's seed (Cranley-Patterson rotation; 0 for seed 0).
// Flux (docs/vpl.md): the power the light delivers to the texel's surface times its albedo,
// times the texels each VPL stands for (W H / n, uniform sampling):
//   directional  E * A_texel                (A_texel: the texel's area across the beam)
//   spot         I(w) * Omega_texel, Omega_texel = A_unit cos^3(alpha) (the texel's solid angle)
// A texel with no surface, or that the light does not reach, is an invalid VPL (flux 0).
#include "common/lights.glsl"
#include "common/vpl.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D rsmPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D rsmNormal;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D rsmAlbedo;
layout(set = 0, binding = 3, scalar) readonly buffer PassLights { PassLight passLights[]; };
layout(set = 0, binding = 4, std430) buffer Vpls { Vpl vpls[]; };

layout(push_constant, std430) uniform Push {
    vec4 axis;      // xyz the view's forward axis, w texel area (world m^2 or unit image plane)
    uint light;     // pass light table entry
    uint count;     // n VPLs
    uint first;     // first VPL written
    uint perspective;
    vec2 shift;     // Cranley-Patterson rotation of the Hammersley points (seed 0: none)
} pc;

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= pc.count) return;
    ivec2 size = imageSize(rsmPosition);
    vec2 u = vplHammersleyShifted(k, pc.count, pc.shift);
    ivec2 texel = min(ivec2(u * vec2(size)), size - 1);
    vec4 p = imageLoad(rsmPosition, texel);
    Vpl v;
    v.position = vec4(p.xyz, 0.0);
    v.normal = vec4(0.0, 0.0, 1.0, -1.0);
    v.flux = vec4(0.0, 0.0, 0.0, 1.0);
    if (p.w > 0.5) {
        PassLight light = passLights[pc.light];
        vec3 wi;
        float dist;
        vec3 ePerp = lightIrradiancePerp(light, p.xyz, wi, dist);
        float area = pc.axis.w;
        if (pc.perspective != 0u) {
            float cosAlpha = max(dot(-wi, pc.axis.xyz), 0.0);
            area *= dist * dist * cosAlpha * cosAlpha * cosAlpha;
        }
        vec3 albedo = imageLoad(rsmAlbedo, texel).rgb;
        float texelsPerVpl = float(size.x) * float(size.y) / float(pc.count);
        vec3 flux = albedo * ePerp * area * texelsPerVpl;
        bool lit = max(flux.r, max(flux.g, flux.b)) > 0.0 && vplFinite(flux) && vplFinite(p.xyz);
        v.position.w = lit ? 1.0 : 0.0;
        v.normal.xyz = imageLoad(rsmNormal, texel).xyz;
        v.flux.rgb = lit ? flux : vec3(0.0);
    }
    vpls[pc.first + k] = v;
}
