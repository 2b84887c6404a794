#version 460
// ddgi "probe_trace" (paper 1 §4.1 steps 1-2; SDK ProbeTraceRGS): one thread per probe ray.
// Traces the GPU BVH from the probe (both faces), shades the hit with the direct light of the
// pass lights (a shadow ray each; emitter samples chosen at random) plus, with feedback, the
// previous update's irradiance (unbounded bounces), and stores (radiance, distance). Misses
// store distance 1e27; back faces store -0.2 t and no radiance (notes 005 §3.2).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 64) in;

#include "common/scene.glsl"
#define RT_SET 1
#define RT_BINDING 10
#include "common/rt_trace.glsl"
#define SHADOW_SET 1
#define SHADOW_BINDING 12
#include "common/lights.glsl"
#include "common/shadow.glsl"
#include "ddgi_common.glsl"
#include "common/random.glsl"

layout(set = DDGI_SET, binding = 3, std430) writeonly buffer ProbeRays { vec4 probeRays[]; };

float random01(inout uint state) {
    state = pcgHash(state);
    return float(state >> 8) * (1.0 / 16777216.0);
}

// Irradiance at x (offset off the surface along nFace) with shading normal ns.
vec3 directIrradiance(vec3 x, vec3 ns, vec3 nFace, inout uint rng) {
    vec3 e = vec3(0.0);
    uint punctual = ddgi.lights.x;
    for (uint l = 0u; l < punctual; ++l) {
        vec3 wi;
        float dist;
        vec3 perp = lightIrradiancePerp(passLights[l], x, wi, dist);
        float c = dot(ns, wi);
        if (c <= 0.0 || dot(nFace, wi) <= 0.0 || max(perp.r, max(perp.g, perp.b)) <= 0.0) continue;
        float tMax = dist >= 1.0e29 ? 1.0e30 : dist * (1.0 - 1.0e-4);
        if (!rtOccluded(x, wi, 0.0, tMax)) e += perp * c;
    }
    uint samples = ddgi.lights.y;
    if (samples == 0u) return e;
    uint taken = min(ddgi.lights.z, samples);
    bool all = taken == samples;
    float weight = float(samples) / float(taken);
    for (uint k = 0u; k < taken; ++k) {
        uint s = all ? k : min(uint(random01(rng) * float(samples)), samples - 1u);
        PassLight light = passLights[punctual + s];
        vec3 wi;
        float dist;
        vec3 perp = lightIrradiancePerp(light, x, wi, dist);
        float c = dot(ns, wi);
        if (c <= 0.0 || dot(nFace, wi) <= 0.0 || max(perp.r, max(perp.g, perp.b)) <= 0.0) continue;
        // The sample lies on its emitter: stop short of it
        float tMax = dist * (1.0 - 1.0e-3) - ddgi.misc.x;
        if (tMax <= 0.0 || !rtOccluded(x, wi, 0.0, tMax)) e += perp * (c * (all ? 1.0 : weight));
    }
    return e;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    uint raysPerProbe = ddgi.texels.z;
    if (i >= ddgi.counts.w * raysPerProbe) return;
    uint probe = i / raysPerProbe;
    uint r = i % raysPerProbe;
    if (ddgiProbeInactive(probe) && r >= ddgi.texels.w) {
        probeRays[i] = vec4(0.0, 0.0, 0.0, 1.0e27);  // not traced, not blended
        return;
    }
    vec3 origin = ddgiProbePosition(probe);
    vec3 dir = ddgiRayDirection(r);
    RtHit hit;
    if (!rtClosest(origin, dir, 0.0, 1.0e27, hit)) {
        probeRays[i] = vec4(0.0, 0.0, 0.0, 1.0e27);  // miss: no sky in gilab scenes
        return;
    }
    vec3 ng = triangleGeometricNormal(hit.triangle);
    float lenNg = length(ng);
    ng = lenNg > 0.0 ? ng / lenNg : -dir;
    Material m = fetchMaterial(hit.triangle);
    bool backFace = dot(ng, dir) > 0.0;
    bool doubleSided = (m.flags & MATERIAL_DOUBLE_SIDED) != 0u;
    if (backFace && !doubleSided) {
        probeRays[i] = vec4(0.0, 0.0, 0.0, -0.2 * hit.t);
        return;
    }
    SceneVertex v = interpolateVertex(hit.triangle, hit.bary);
    vec3 nFace = backFace ? -ng : ng;  // the side the probe sees
    vec3 ns = dot(v.normal, nFace) < 0.0 ? -v.normal : v.normal;
    vec3 x = origin + hit.t * dir;
    vec3 xo = x + nFace * ddgi.misc.x;
    vec2 metalRough = sampleMetalRough(m, v.uv);
    vec3 albedo = sampleBaseColorLod(m, v.uv, ddgi.misc.z).rgb * (1.0 - metalRough.x);

    uint rng = pcgHash(i ^ pcgHash(ddgi.lights.w * 9781u + ddgi.size.z));
    vec3 radiance = albedo / DDGI_PI * directIrradiance(xo, ns, nFace, rng);
    if (ddgi.flags.x != 0u)
        radiance += albedo / DDGI_PI * ddgi.blend.w * ddgiIrradiance(x, ns, -dir);
    if (ddgi.flags.y != 0u) radiance += sampleEmission(m, v.uv);
    probeRays[i] = vec4(max(radiance, vec3(0.0)), hit.t);
}
