// One photon of the light-view map (notes 001 §2.5): a light-map texel's surface hit, carrying the
// radiant flux that reaches the surface through the texel's solid angle. Written by the injection
// pass of `vct` (techniques/vct/light_injection.h), read by the dense and the octree splats.
// Mirrored by gilab::vct::GpuPhoton (48 bytes, std430).
#ifndef GILAB_VCT_PHOTON_GLSL
#define GILAB_VCT_PHOTON_GLSL

struct Photon {
    vec4 positionValid;  // xyz world position of the hit, w = 1 valid / 0 no photon (missed)
    vec4 flux;           // rgb radiant flux in W arriving at the surface, w unused
    vec4 toLight;        // xyz unit direction from the surface toward the light, w unused
};

#endif  // GILAB_VCT_PHOTON_GLSL
