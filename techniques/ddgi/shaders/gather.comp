#version 460
// ddgi "gather" (paper 1 §5; SDK IndirectCS with DDGIGetVolumeIrradiance): per pixel of the
// shared G-buffer, the 8-probe irradiance query at the pixel's point and normal, times the
// diffuse albedo / pi, written to the indirect layer (linear HDR radiance).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "ddgi_common.glsl"

layout(set = DDGI_SET, binding = 5, rgba32f) readonly uniform image2D gPosition;
layout(set = DDGI_SET, binding = 6, rgba32f) readonly uniform image2D gNormal;
layout(set = DDGI_SET, binding = 7, rgba32f) readonly uniform image2D gAlbedo;
layout(set = DDGI_SET, binding = 8, rgba32f) readonly uniform image2D gMaterial;
layout(set = DDGI_SET, binding = 9, rgba32f) writeonly uniform image2D outIndirect;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(ddgi.size.x) || pixel.y >= int(ddgi.size.y)) return;
    vec4 position = imageLoad(gPosition, pixel);
    if (position.w == 0.0) {
        imageStore(outIndirect, pixel, vec4(0.0, 0.0, 0.0, 1.0));
        return;
    }
    vec3 n = imageLoad(gNormal, pixel).xyz;
    float lenN = length(n);
    if (!(lenN > 0.0)) {
        imageStore(outIndirect, pixel, vec4(0.0, 0.0, 0.0, 1.0));
        return;
    }
    n /= lenN;
    vec3 x = position.xyz;
    vec3 toEye = ddgi.camera.xyz - x;
    float lenEye = length(toEye);
    vec3 wo = lenEye > 0.0 ? toEye / lenEye : n;
    vec3 albedo = imageLoad(gAlbedo, pixel).rgb * (1.0 - imageLoad(gMaterial, pixel).x);
    vec3 e = ddgiIrradiance(x, n, wo);
    imageStore(outIndirect, pixel, vec4(albedo / DDGI_PI * e, 1.0));
}
