#version 460
#extension GL_GOOGLE_include_directive : require
// Octree injection, step 1 (techniques/vct/svo.md "Injection"): the photon range of every
// light, so that the splat can run once per light (count pass, then E / count pass) with indirect
// dispatches. pc.args: x photons, y lights, z pass, w groups per row (maxComputeWorkGroupCount).
//   pass 0, one thread per photon i of light l = irradiance.w: atomicMax of i + 1 into word END
//     and of (photons - i) into word FIRST (svoLights cleared to 0 before), so a light's photons
//     need not even be contiguous (the splat skips the other lights' photons inside the range);
//   pass 1, one thread per light: first = photons - FIRST, the range [first, end) and its
//     dispatch (x, y, 1) groups of SVO_GROUP_SIZE (2D past the group limit, svoThread()).
#include "svo_common.glsl"

layout(set = 2, binding = 0, std430) readonly buffer Photons {
    Photon photons[];
};
layout(local_size_x = SVO_GROUP_SIZE) in;

void main() {
    uint i = svoThread();
    uint count = pc.args.x, lights = pc.args.y;
    if (pc.args.z == 0u) {
        if (i >= count) return;
        float w = photons[i].irradiance.w;
        if (!(w >= 0.0) || w + 0.5 >= float(lights)) return;
        uint l = uint(w + 0.5);
        atomicMax(svoLights[l * SVO_LIGHT_WORDS + SVO_LIGHT_END], i + 1u);
        atomicMax(svoLights[l * SVO_LIGHT_WORDS + SVO_LIGHT_FIRST], count - i);
        return;
    }
    if (i >= lights) return;
    uint base = i * SVO_LIGHT_WORDS;
    uint first = count - svoLights[base + SVO_LIGHT_FIRST];
    uint end = svoLights[base + SVO_LIGHT_END];
    uint n = end > first ? end - first : 0u;
    uint groups = (n + SVO_GROUP_SIZE - 1u) / SVO_GROUP_SIZE;
    uint x = min(groups, max(pc.args.w, 1u));
    uint y = x > 0u ? (groups + x - 1u) / x : 0u;
    svoLights[base + 0u] = x;
    svoLights[base + 1u] = y;
    svoLights[base + 2u] = 1u;
    svoLights[base + SVO_LIGHT_FIRST] = first;
    svoLights[base + SVO_LIGHT_END] = end;
}
