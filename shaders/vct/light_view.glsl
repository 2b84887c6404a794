// One light-view map layer of vct's light injection (techniques/vct/light_injection.h, notes 001
// §2.5). Mirrored by gilab::vct::GpuLightView (176 bytes, std430).
#ifndef GILAB_VCT_LIGHT_VIEW_GLSL
#define GILAB_VCT_LIGHT_VIEW_GLSL

struct LightView {
    mat4 viewProj;      // world -> Vulkan clip space (reversed Z)
    vec4 positionKind;  // xyz light position (perspective) or map centre (ortho); w 0 persp, 1 ortho
    vec4 forward;       // texel ray (or ortho direction) = forward + ndc.x * axisX + ndc.y * axisY
    vec4 axisX;         // w: tan(half fov) (perspective) or half width (orthographic)
    vec4 axisY;
    vec4 intensity;     // rgb W/sr (point, spot) or W/m^2 (directional)
    vec4 spotAxis;      // xyz spot travel direction, w 1 = spot falloff applies
    vec4 cone;          // x cos(inner), y cos(outer), z scene light index
};

#endif  // GILAB_VCT_LIGHT_VIEW_GLSL
