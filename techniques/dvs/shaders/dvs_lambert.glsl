// Per-voxel diffuse terms of deferred voxel shading (notes 003 §2.4), shared by voxel_direct.comp
// and the tests' hand-checked values (techniques/dvs/README.md).
#ifndef GILAB_DVS_LAMBERT_GLSL
#define GILAB_DVS_LAMBERT_GLSL

#define DVS_LAMBERT_NORMAL_WEIGHTED 0u
#define DVS_LAMBERT_COSINE 1u

// Expected max(N.Psi, 0) over uniformly random orientations (1/4): the "isotropic" term used
// when a voxel's averaged normal vanished (opposite faces in one voxel, notes 003 §6).
#define DVS_ISOTROPIC_LAMBERT 0.25

// Normal-weighted Lambert, notes 003 E1-E3: D = (i.Psi, j.Psi, k.Psi); per axis
// D_w = max(D_w, 0) if N_w > 0 else max(-D_w, 0); result = sum_w N_w^2 D_w (sum N^2 = 1 for unit N).
// Psi points toward the light. The 1/pi and rho are applied by the caller.
float dvsNormalWeightedLambert(vec3 n, vec3 psi) {
    vec3 d = mix(max(-psi, vec3(0.0)), max(psi, vec3(0.0)), greaterThan(n, vec3(0.0)));
    return dot(n * n, d);
}

float dvsLambert(uint mode, vec3 n, vec3 psi) {
    return mode == DVS_LAMBERT_COSINE ? max(dot(n, psi), 0.0) : dvsNormalWeightedLambert(n, psi);
}

#endif  // GILAB_DVS_LAMBERT_GLSL
