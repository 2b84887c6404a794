// One photon of the light-view map (notes 001 §2.5): a light-map texel's surface hit, carrying the
// radiant flux that reaches the surface through the texel's solid angle and the irradiance the
// light produces at the hit. Written by the injection pass of `vct`
// (techniques/vct/light_injection.h), read by the dense and the octree splats.
// Mirrored by gilab::vct::GpuPhoton (80 bytes, std430; techniques/vct/photons.h).
#ifndef GILAB_VCT_PHOTON_GLSL
#define GILAB_VCT_PHOTON_GLSL

struct Photon {
    vec4 positionValid;  // xyz world position of the hit, w = 1 valid / 0 no photon (missed)
    vec4 flux;           // rgb radiant flux in W through the texel (0 if back-facing), w unused
    vec4 toLight;        // xyz unit direction from the surface toward the light, w unused
    vec4 irradiance;     // rgb irradiance E in W/m^2 on the surface at the hit (receiver cosine
                         // included, 0 if back-facing or missed), w = light index (float)
    vec4 normal;         // xyz unit shading normal on the light's side (0 for a miss), w = 1 if
                         // the surface faces the light (n . toLight > 0), else 0
};

#endif  // GILAB_VCT_PHOTON_GLSL
