// Leaf shading after the irradiance transfer (the dense path's formula, inject_shade_body.glsl):
// rgb = a albedo / pi * E (premultiplied outgoing diffuse radiance; E = sum over lights of the
// light's mean photon irradiance, svo_splat_body.glsl), a = coverage, from the geometry brick
// (a albedo, a), written to the leaf's radiance slot. One thread per leaf sample.
#include "svo_common.glsl"

layout(local_size_x = SVO_GROUP_SIZE) in;

void main() {
    uint d = svo.dims.y;
    uint t = svoThread();
    uint node = svoLevelBegin(d) + t / 27u;
    if (node >= svoLevelEnd(d)) return;
    uint brick = svoWord(node, SVO_W_BRICK);
    if (brick == SVO_NONE) return;
    uint k = t % 27u;
    ivec3 s = ivec3(int(k % 3u), int((k / 3u) % 3u), int(k / 9u));
    uint slot = svoWord(node, SVO_W_RADIANCE);
    if (slot == SVO_NONE) return;
    vec4 g = imageLoad(svoGeometry, svoBrickOrigin(brick) + s);
    uint base = (brick * 27u + k) * 3u;
#ifdef SVO_FLOAT_ACCUM
    vec3 e = vec3(svoAccum[base], svoAccum[base + 1u], svoAccum[base + 2u]);
#else
    vec3 e = vec3(svoAccum[base], svoAccum[base + 1u], svoAccum[base + 2u]) * pc.scale.y;
#endif
    e = max(e, vec3(0.0));
    // RGBA16F saturates at 65504: clamp there rather than store Inf (as the dense shade)
    vec3 rgb = g.a > 0.0 ? min(g.rgb * e * pc.scale.z, vec3(65504.0)) : vec3(0.0);
    imageStore(svoRadiance, svoRadianceOrigin(slot) + s, vec4(rgb, g.a));
}
