// One light-view map of vct's light injection (techniques/vct/light_injection.h, notes 001
// §2.5). Mirrored by gilab::vct::GpuLightView (224 bytes, std430).
//
// Texel (x, y) of a W x H map has ndc = ((x, y) + 0.5) / (W, H) * 2 - 1 and
//   pinhole (w = 0):      ray = forward + ndc.x * axisX + ndc.y * axisY from positionKind.xyz;
//                         forward, axisX, axisY lie on the image plane at unit distance along
//                         the plane normal normalize(cross(axisX, axisY)) (an off-centre window
//                         when forward is not that normal, e.g. a hemicube's half side faces)
//   orthographic (w = 1): the ray along forward through positionKind.xyz + ndc.x * axisX +
//                         ndc.y * axisY (axisX, axisY: world half-extent vectors)
#ifndef GILAB_VCT_LIGHT_VIEW_GLSL
#define GILAB_VCT_LIGHT_VIEW_GLSL

// Emission lobes (LightView.intensity.w).
#define LIGHT_VIEW_LOBE_UNIFORM 0     // point light: I
#define LIGHT_VIEW_LOBE_SPOT 1        // spot: I * glTF falloff around spotAxis
#define LIGHT_VIEW_LOBE_COSINE 2      // emitter sample: I * max(0, spotAxis . w)
#define LIGHT_VIEW_LOBE_COSINE_2S 3   // double-sided emitter sample: I * |spotAxis . w|

struct LightView {
    mat4 viewProj;      // world -> Vulkan clip space (reversed Z)
    vec4 positionKind;  // xyz light position (pinhole) or window centre (ortho); w 0 pinhole, 1 ortho
    vec4 forward;       // xyz see above (ortho: the direction light travels)
    vec4 axisX;         // xyz half-extent vector, w its length
    vec4 axisY;
    vec4 intensity;     // rgb W/sr (point, spot, emitter sample along its normal) or W/m^2
                        // (directional); w LIGHT_VIEW_LOBE_*
    vec4 spotAxis;      // xyz spot travel direction or emitter normal; w 1 = spot falloff applies
    vec4 cone;          // x cos(inner), y cos(outer), z scene light index (-1 - k: emitter sample
                        // k), w skip distance (emitter samples: surfaces closer than this to
                        // the plane skipPlane are not rendered; 0 = none)
    vec4 skipPlane;     // xyz unit normal, w offset: plane dot(xyz, p) + w = 0
    uvec4 texels;       // x width, y height (texels), z first photon of the view in its batch,
                        // w map layer in its batch
    uvec4 group;        // x light index, y its first view, z its view count, w batch
};

// Push constants of the light-view raster (light_view.vert/.frag, define LIGHT_VIEW_RASTER);
// mirrored by LightViewPush in techniques/vct/light_injection.cpp.
#ifdef LIGHT_VIEW_RASTER
layout(push_constant, std430) uniform LightViewPush {
    mat4 viewProj;   // world -> clip (reversed Z)
    vec4 toLight;    // xyz light position (w = 0) or unit direction toward the light (w = 1)
    vec4 skipPlane;  // xyz unit normal, w offset (emitter samples)
    vec4 skip;       // x: fragments closer than this to skipPlane are not rendered (0 = none)
} pc;
#endif

#endif  // GILAB_VCT_LIGHT_VIEW_GLSL
