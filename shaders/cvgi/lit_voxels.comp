#version 460
#extension GL_GOOGLE_include_directive : require
// Emitter update, step 2a (§4.4, Fig. 10): a voxel is lit when any of its 18 test points (face and
// edge centres pushed 1.5 s from its centre) is seen by the emitter's distance map, unless it is
// behind an occupied neighbour toward the light (Fig. 10 right; our reading below), and only
// where the light reaches it: its radiosity B = albedo * E, with E the light's irradiance at the
// centre on the mean fragment normal, must be above 0 (outside a spot's cone, or facing away, a
// voxel is not lit). B is added to voxelLight (one dispatch per emitter). Radiometry:
// docs/conventions.md, lights.glsl.
#include "cvgi/cvgi_common.glsl"

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
    if (lit && u.options.y != 0u) {
        // "An occupied neighbor in the light direction" (Fig. 10), read as: the voxel is buried
        // toward the light on every axis the light comes from (each axis neighbour whose
        // to-light component exceeds 0.2 is occupied), or the neighbour across its own lit
        // face (the heuristic normal, when it faces the light) is occupied. The dominant axis
        // alone rejected every wall voxel lit at an angle: its neighbour along that axis is the
        // next voxel of the same wall (docs/techniques/cvgi.md, "Lit voxels").
        bool buried = true;
        bool any = false;
        for (int axis = 0; axis < 3; ++axis) {
            if (abs(wi[axis]) <= 0.2) continue;
            ivec3 step = ivec3(0);
            step[axis] = wi[axis] > 0.0 ? 1 : -1;
            any = true;
            buried = buried && cvgiIndexAt(c + step) != CVGI_EMPTY;
        }
        ivec3 face = cvgiAxisDir(cvgiAxis(i));
        bool faceCovered = dot(vec3(face), wi) > 0.0 && cvgiIndexAt(c + face) != CVGI_EMPTY;
        if ((any && buried) || faceCovered) lit = false;
    }
    if (!lit) return;
    CvgiVoxel v = voxels[i];
    vec3 n = v.normalCluster.xyz;
    if (dot(n, n) < 1e-6) n = vec3(cvgiAxisDir(cvgiAxis(i)));
    vec3 b = v.albedoAxis.rgb * ePerp * max(dot(normalize(n), wi), 0.0);
    if (!(b.r + b.g + b.b > 0.0)) return;  // the light does not reach it
    voxelLight[i] += vec4(b, 1.0);
}
