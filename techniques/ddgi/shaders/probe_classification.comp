#version 460
// ddgi "probe_classification" (paper 2; SDK ProbeClassificationCS), one thread per probe, on
// the fixed rays: inactive when the back-face share is above the threshold (inside geometry),
// or when no fixed ray hits a front face before it leaves the probe's cell (planes one spacing
// away along each axis): such a probe cannot contribute to shading in its cell. Inactive probes
// trace only the fixed rays, are not blended and are skipped by the query.
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
    bool nearSurface = false;
    vec3 spacing = ddgi.gridSpacing.xyz;
    for (uint r = 0u; r < fixedRays; ++r) {
        float d = probeRays[first + r].w;
        if (d < 0.0) {
            ++backFaces;
            continue;
        }
        vec3 dir = abs(ddgiRayDirection(r));
        vec3 tCell = spacing / max(dir, vec3(1e-6));
        if (d <= min(tCell.x, min(tCell.y, tCell.z))) nearSurface = true;
    }
    bool inside = float(backFaces) / float(fixedRays) > ddgi.thresholds.z;
    probeData[probe].w = (inside || !nearSurface) ? DDGI_PROBE_INACTIVE : DDGI_PROBE_ACTIVE;
}
