#version 460
#extension GL_GOOGLE_include_directive : require
// Edge-aware separable Gaussian of the VPL irradiance, then the albedo (core/vpl/vpl_shading.h;
// Aranha et al. §III-D: the irradiance is denoised before the albedo is applied, so texture
// detail is not blurred). Weight of a neighbour q of p: Gaussian(sigma = radius / 2) x
// max(n_p . n_q, 0)^32 x exp(-(plane distance / (0.1 |q - p|))^2), plane distance =
// |n_p . (q - p)|; background pixels take no part. Passes (push mode):
//   0  horizontal, irradiance -> temp
//   1  vertical, temp -> output, output = albedo / pi x E (outgoing diffuse radiance)
//   2  no blur, irradiance -> output, output = albedo / pi x E
#include "common/vpl.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(set = 0, binding = 3, rgba32f) uniform image2D irradianceImage;
layout(set = 0, binding = 4, rgba32f) uniform image2D tempImage;
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D outputImage;

layout(push_constant, std430) uniform Push {
    uint mode;
    int radius;
} pc;

vec3 loadSource(ivec2 q) {
    return pc.mode == 1u ? imageLoad(tempImage, q).rgb : imageLoad(irradianceImage, q).rgb;
}

void main() {
    ivec2 size = imageSize(irradianceImage);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, size))) return;
    vec4 pos = imageLoad(gPosition, px);
    vec3 e = loadSource(px);
    if (pos.w > 0.5 && pc.mode != 2u && pc.radius > 0) {
        vec3 n = imageLoad(gNormal, px).xyz;
        ivec2 axis = pc.mode == 0u ? ivec2(1, 0) : ivec2(0, 1);
        float sigma = max(0.5 * float(pc.radius), 0.5);
        vec3 sum = vec3(0.0);
        float wsum = 0.0;
        for (int k = -pc.radius; k <= pc.radius; ++k) {
            ivec2 q = px + k * axis;
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec4 qp = imageLoad(gPosition, q);
            if (qp.w < 0.5) continue;
            vec3 qn = imageLoad(gNormal, q).xyz;
            vec3 dp = qp.xyz - pos.xyz;
            float plane = abs(dot(n, dp)) / (0.1 * length(dp) + 1e-12);
            float w = exp(-0.5 * float(k * k) / (sigma * sigma)) *
                      pow(max(dot(n, qn), 0.0), 32.0) * exp(-plane * plane);
            if (k == 0) w = 1.0;
            sum += w * loadSource(q);
            wsum += w;
        }
        e = sum / wsum;
    }
    if (pc.mode == 0u) {
        imageStore(tempImage, px, vec4(e, 1.0));
    } else {
        vec3 albedo = imageLoad(gAlbedo, px).rgb;
        imageStore(outputImage, px, vec4(pos.w > 0.5 ? albedo / VPL_PI * e : vec3(0.0), 1.0));
    }
}
