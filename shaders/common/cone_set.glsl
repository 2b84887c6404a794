// Diffuse cone set (core/voxel/cone_set.h, docs/voxel_cone_tracing.md). Mirrors gilab::GpuConeSet:
// cones[i].xyz = unit direction in tangent space (+z = surface normal), cones[i].w = weight
// (sum of weights = pi, notes 003 E14); info.x = cone count, info.y = tan(aperture / 2).
#ifndef GILAB_CONE_SET_GLSL
#define GILAB_CONE_SET_GLSL

#define CONE_SET_MAX 16

struct ConeSetData {
    vec4 cones[CONE_SET_MAX];
    vec4 info;
};

uint coneSetCount(ConeSetData s) { return min(uint(s.info.x + 0.5), uint(CONE_SET_MAX)); }
float coneSetTanHalf(ConeSetData s) { return s.info.y; }
vec3 coneSetDirection(ConeSetData s, uint i) { return s.cones[i].xyz; }
float coneSetWeight(ConeSetData s, uint i) { return s.cones[i].w; }

#endif  // GILAB_CONE_SET_GLSL
