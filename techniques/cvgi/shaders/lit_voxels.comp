#version 460
#extension GL_GOOGLE_include_directive : require
// Emitter update, step 2a (§4.4, Fig. 10): a voxel is lit when any of its 18 test points (face and
// edge centres pushed 1.5 s from its centre) is seen by the emitter's distance map, unless it is
// behind an occupied neighbour toward the light (Fig. 10 right; our reading below), and only
// where the light reaches it: its radiosity B = albedo * E, with E the light's irradiance at the
// centre on the mean fragment normal, must be above 0 (outside a spot's cone, or facing away, a
// voxel is not lit). B is added to voxelLight (one dispatch per emitter). Radiometry:
// docs/conventions.md, lights.glsl.
#include "cvgi_common.glsl"

layout(local_size_x = 64) in;

layout(push_constant, std430) uniform Push {
    mat4 viewProj;
    vec4 origin;     // w 1 = orthographic
    vec4 direction;
    uvec4 light;     // x pass light index
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u.counts.x) return;
    ivec3 c = cvgiCoord(i);
    float s = voxelSize(u.grid);
    vec3 centre = voxelCenterWorld(u.grid, c);
    bool lit = false;
    for (uint k = 0u; k < 18u && !lit; ++k) {
        vec3 p = centre + 1.5 * s * cvgiTestDirection(k);
        lit = cvgiSeen(emitterMap, pc.viewProj, pc.origin, pc.direction.xyz, p,
                       u.biases.x * s);
    }
    PassLight light = passLights[pc.light.x];
    vec3 wi;
    float dist;
    vec3 ePerp = lightIrradiancePerp(light, centre, wi, dist);
    CvgiVoxel v = voxels[i];
    vec3 n = v.normalCluster.xyz;
    if (lit && u.options.y != 0u) {
        // "An occupied neighbor in the light direction" (Fig. 10), read as: the neighbour the
        // light direction points to (the 26-neighbour c + round(wi)) is occupied and is not
        // part of this voxel's own surface. A neighbour belongs to the surface when the plane
        // of the voxel's mean normal n, through a point at most half the way from the centre
        // to the cube's boundary, also crosses the neighbour's cube: |n.step| < 0.75 |n|_1
        // (voxel units; the next voxel of the same wall, floor or slope, including the second
        // voxel of a sloped surface's staircase column). Issue 43: the previous reading
        // (buried on every axis with |wi_k| > 0.2, or across the heuristic face) rejected
        // every wall voxel under a steep sun and half of every slope (cvgi held 0.51 of the
        // reflected power `gilab bench light-power` traces on Sponza's sun; techniques/cvgi/
        // README.md, "Lit voxels").
        ivec3 step = ivec3(round(wi));
        if (step != ivec3(0) && cvgiIndexAt(c + step) != CVGI_EMPTY) {
            float len = length(n);
            vec3 m = len > 0.5 ? n / len : vec3(0.0);
            float l1 = abs(m.x) + abs(m.y) + abs(m.z);
            bool ownSurface = len > 0.5 && abs(dot(m, vec3(step))) < 0.75 * l1;
            if (!ownSurface) lit = false;
        }
    }
    if (!lit) return;
    if (dot(n, n) < 1e-6) n = vec3(cvgiAxisDir(cvgiAxis(i)));
    vec3 b = v.albedoAxis.rgb * ePerp * max(dot(normalize(n), wi), 0.0);
    if (!(b.r + b.g + b.b > 0.0)) return;  // the light does not reach it
    voxelLight[i] += vec4(b, 1.0);
}
