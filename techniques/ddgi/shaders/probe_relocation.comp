#version 460
// ddgi "probe_relocation" (paper 2; SDK ProbeRelocationCS), one thread per probe, on the 32
// fixed rays (notes 005 §5). With D = the min front-face distance:
//   1. back-face share > threshold (inside geometry): move through the closest back face,
//      by its distance + D/2;
//   2. else a front face closer than D, with the closest and farthest front faces on opposite
//      sides: step toward the farthest by min(its distance, D) (SDK: min(distance, 1 m) with
//      D = 1 m by default; here D scales with the spacing);
//   3. else (closest front face farther than D): move back toward the grid point by
//      min(closest - D, |offset|).
// A new offset is kept only while |offset / spacing| < 0.45 (the probe stays in its cell).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#define DDGI_PROBES_WRITABLE
#include "ddgi_common.glsl"

layout(set = DDGI_SET, binding = 3, std430) readonly buffer ProbeRays { vec4 probeRays[]; };

void main() {
    uint probe = gl_GlobalInvocationID.x;
    if (probe >= ddgi.counts.w) return;
    uint fixedRays = ddgi.texels.w;
    uint first = probe * ddgi.texels.z;
    uint backFaces = 0u;
    float closestBack = 1.0e27, closestFront = 1.0e27, farthestFront = 0.0;
    vec3 closestBackDir = vec3(0.0), closestFrontDir = vec3(0.0), farthestFrontDir = vec3(0.0);
    for (uint r = 0u; r < fixedRays; ++r) {
        float d = probeRays[first + r].w;
        vec3 dir = ddgiRayDirection(r);
        if (d < 0.0) {
            ++backFaces;
            float t = -d * 5.0;  // undo the 0.2 shortening
            if (t < closestBack) {
                closestBack = t;
                closestBackDir = dir;
            }
        } else {
            if (d < closestFront) {
                closestFront = d;
                closestFrontDir = dir;
            }
            if (d > farthestFront) {
                farthestFront = d;
                farthestFrontDir = dir;
            }
        }
    }
    vec3 offset = probeData[probe].xyz;
    float minFront = ddgi.misc.y;
    vec3 candidate = offset;
    if (float(backFaces) / float(fixedRays) > ddgi.thresholds.z) {
        candidate = offset + closestBackDir * (closestBack + 0.5 * minFront);
    } else if (closestFront < minFront) {
        if (dot(closestFrontDir, farthestFrontDir) <= 0.0)
            candidate = offset + farthestFrontDir * min(farthestFront, minFront);
    } else if (closestFront > minFront) {
        float len = length(offset);
        if (len > 0.0) candidate = offset - offset / len * min(closestFront - minFront, len);
    }
    vec3 normalized = candidate / ddgi.gridSpacing.xyz;
    if (dot(normalized, normalized) < 0.45 * 0.45) probeData[probe].xyz = candidate;
}
