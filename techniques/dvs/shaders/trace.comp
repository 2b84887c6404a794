#version 460
#extension GL_GOOGLE_include_directive : require
// DVS pass P1, per-pixel voxel cone tracing from the G-buffer (notes 003 §2.8), one thread per
// pixel. Writes the indirect layer:
//   diffuse  (rho (1 - metallic) / pi) * sum_i w_i L_i      (E14, sum w = pi, no GI strength)
//   specular F0 * L_spec, one cone along reflect(-wo, n)    (glossy pixels, when enabled)
// and optionally: AO (E11-E12) into the debug view, the direct layer recomputed with cone
// shadows (E13, same lights.glsl / brdf.glsl light model as the shared pass), and the source's
// (direct + indirect) * AO composition.
#include "common/brdf.glsl"
#include "common/cone_set.glsl"
#include "common/voxel_grid.glsl"
#define SHADOW_SET 0
#define SHADOW_BINDING 8
#include "common/shadow.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gPosition;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D gNormal;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D gMaterial;
layout(set = 0, binding = 4, rgba32f) uniform writeonly image2D outIndirect;
layout(set = 0, binding = 5, rgba32f) uniform image2D ioDirect;
layout(set = 0, binding = 6, rgba32f) uniform writeonly image2D outAo;
layout(set = 0, binding = 7, std140) uniform TraceUniforms {
    VoxelGridInfo grid;
    vec4 coneParams[4];  // ConeTraceParams (voxel_cone.glsl)
    ConeSetData diffuse;
    vec4 camera;    // xyz eye, w origin offset along the normal (world)
    vec4 specular;  // x 1 = on, y fixed tan(theta/2) (0 = from roughness)
    vec4 shadow;    // x shadow cone tan(theta/2), y AO lambda (1/world, diffuse cones)
    uvec4 size;     // x width, y height, z pass light count
    uvec4 flags;    // x 1 = cone shadows, y 1 = source composition, z 1 = AO
} u;

VoxelGridInfo voxelConeGrid() { return u.grid; }
bool voxelConeAnisotropic() { return true; }
#define VOXEL_CONE_SET 0
#define VOXEL_CONE_BINDING 12
#include "common/voxel_cone_dense.glsl"

// Specular aperture from GGX roughness (dvsSpecularApertureDeg in dvs_settings.cpp): Phong
// exponent 2/alpha^2 - 2, half angle arccos(0.5^(1/n)), full angle clamped to [1, 60] deg.
float specularTanHalf(float roughness) {
    float alpha = max(roughness * roughness, BRDF_MIN_ALPHA);
    float exponent = 2.0 / (alpha * alpha) - 2.0;
    float halfAngle = exponent > 1.0e-4 ? acos(pow(0.5, 1.0 / exponent)) : 0.5 * BRDF_PI;
    halfAngle = clamp(halfAngle, radians(0.5), radians(30.0));
    return tan(halfAngle);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(u.size.x) || pixel.y >= int(u.size.y)) return;
    vec4 position = imageLoad(gPosition, pixel);
    if (!(position.w > 0.0)) {
        imageStore(outIndirect, pixel, vec4(0.0, 0.0, 0.0, 1.0));
        imageStore(outAo, pixel, vec4(0.0, 0.0, 0.0, 1.0));
        return;
    }
    vec3 x = position.xyz;
    vec3 n = imageLoad(gNormal, pixel).xyz;
    vec3 albedo = imageLoad(gAlbedo, pixel).rgb;
    vec2 metalRough = imageLoad(gMaterial, pixel).xy;
    vec3 wo = normalize(u.camera.xyz - x);
    ConeTraceParams p = ConeTraceParams(u.coneParams[0], u.coneParams[1], u.coneParams[2],
                                        u.coneParams[3]);
    ConeSurface surface = ConeSurface(x, n);  // cones leave (x, n): offset + lift
    float offset = u.camera.w;

    // Diffuse cones (E14) and AO (E11-E12) over the same set.
    vec3 diffuseAlbedo = albedo * (1.0 - metalRough.x);
    float tanHalf = coneSetTanHalf(u.diffuse);
    vec3 gathered = vec3(0.0);
    float visibility = 0.0;
    float weightSum = 0.0;
    bool wantAo = u.flags.z != 0u;
    bool wantDiffuse = any(greaterThan(diffuseAlbedo, vec3(0.0)));
    for (uint i = 0u; i < coneSetCount(u.diffuse); ++i) {
        vec3 dir = coneToWorld(coneSetDirection(u.diffuse, i), n);
        float w = coneSetWeight(u.diffuse, i);
        if (wantDiffuse) gathered += w * traceSurfaceCone(surface, offset, dir, tanHalf, p).rgb;
        if (wantAo) {
            ConeTraceParams pa = p;
            pa.distances.w = u.shadow.y;
            visibility +=
                w * traceSurfaceConeVisibility(surface, offset, dir, tanHalf, pa.distances.x, pa);
        }
        weightSum += w;
    }
    vec3 indirect = diffuseAlbedo * (1.0 / BRDF_PI) * gathered;
    float ao = wantAo && weightSum > 0.0 ? clamp(visibility / weightSum, 0.0, 1.0) : 1.0;

    // Specular cone along the reflected view direction, times F0.
    if (u.specular.x > 0.5 && brdfIsGlossy(metalRough.x, metalRough.y)) {
        vec3 r = reflect(-wo, n);
        float tanSpec = u.specular.y > 0.0 ? u.specular.y : specularTanHalf(metalRough.y);
        vec3 f0 = mix(vec3(0.04), albedo, metalRough.x);
        indirect += f0 * traceSurfaceCone(surface, offset, r, tanSpec, p).rgb;
    }

    // Direct light with cone shadows (replaces the shared direct layer).
    bool source = u.flags.y != 0u;
    if (u.flags.x != 0u || source) {
        vec3 direct = imageLoad(ioDirect, pixel).rgb;
        if (u.flags.x != 0u) {
            direct = vec3(0.0);
            for (uint i = 0u; i < u.size.z; ++i) {
                PassLight light = passLights[i];
                vec3 wi;
                float dist;
                vec3 ePerp = lightIrradiancePerp(light, x, wi, dist);
                float cosTheta = dot(n, wi);
                if (cosTheta <= 0.0 || all(equal(ePerp, vec3(0.0)))) continue;
                float maxDist = uint(light.positionType.w) == PASS_LIGHT_DIRECTIONAL
                                    ? p.distances.x
                                    : dist - p.gridMinV0.w;
                // Soft-shadow cone toward the light (notes 003 §4.3, E13 with k = 1): opacity
                // only, up to the light; the shared march (lambda = 0 in p).
                float vis = traceSurfaceConeVisibility(surface, offset, wi, u.shadow.x, maxDist, p);
                if (vis <= 0.0) continue;
                vec3 f = evalBrdf(n, wi, wo, albedo, metalRough.x, metalRough.y);
                direct += f * ePerp * (cosTheta * vis);
            }
        }
        if (source) direct *= ao;  // (direct + indirect) * AO, notes 003 §2.8 (repo mode 0)
        imageStore(ioDirect, pixel, vec4(direct, 1.0));
    }
    if (source) indirect *= ao;
    imageStore(outIndirect, pixel, vec4(indirect, 1.0));
    imageStore(outAo, pixel, vec4(vec3(ao), 1.0));
}
