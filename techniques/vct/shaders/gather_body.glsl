// Per-pixel gather of vct (Crassin et al. 2011 §3, §6, §8.1; notes 001 §2.9, §2.11, §2.12):
// one thread per G-buffer pixel traces the diffuse cone set, optionally a specular cone and AO
// cones, and writes the indirect radiance (one bounce) into outIndirect.
//
// CONTRACT for the includer (dense: gather_dense.comp; octree: svo_gather.comp):
//   1. #version 460, GL_GOOGLE_include_directive.
//   2. #include "gather_inputs.glsl"  -> set 0 (bindings 0..6: G-buffer, indirect output,
//      AO output, uniform GatherParams with the ConeTraceParams, the cone set, flags and the
//      VoxelGridInfo; also voxelConeGrid() and voxelConeAnisotropic()).
//   3. Declare the voxel data in set 1 starting at binding 0 and define
//        vec4 voxelConeSample(vec3 worldPos, float lod, vec3 dir);
//      (premultiplied radiance rgb + opacity a at level lod, 0 = finest voxel size v0).
//   4. #include "gather_body.glsl" (it includes common/voxel_cone.glsl, which is guarded, and
//      defines main with local size 8 x 8).
//
//   indirect = (albedo (1 - metallic) / pi) * sum_i w_i L_i                 (sum w_i = pi)
//            + F0 * L_spec      (glossy pixels, specular flag; F0 = mix(0.04, albedo, metallic))
//   specular aperture: Phong n = 2 / alpha^2 - 2 from GGX alpha = roughness^2, half-max mapping
//   theta / 2 = acos(0.5^(1/n)), clamped to [min, max] aperture (notes 001 §2.11).
//   AO (debug view only): sum_i w_i V_i / pi with V_i = traceConeOcclusion (falloff 1/(1+lambda r)).
#include "common/brdf.glsl"
#include "common/voxel_cone.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

ConeTraceParams gatherConeParams() {
    ConeTraceParams p;
    p.gridMinV0 = gather.gridMinV0;
    p.gridMaxStep = gather.gridMaxStep;
    p.distances = gather.distances;
    p.misc = gather.misc;
    return p;
}

// Full aperture (radians) of the specular cone for a GGX roughness.
float specularAperture(float roughness) {
    float alpha = max(roughness * roughness, BRDF_MIN_ALPHA);
    float n = max(2.0 / (alpha * alpha) - 2.0, 1e-3);
    float halfAngle = acos(clamp(pow(0.5, 1.0 / n), 0.0, 1.0));
    return clamp(2.0 * halfAngle, gather.specular.x, gather.specular.y);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(gather.sizeFlags.x) || pixel.y >= int(gather.sizeFlags.y)) return;
    uint flags = gather.sizeFlags.z;
    vec4 position = imageLoad(gPosition, pixel);
    vec3 n = imageLoad(gNormal, pixel).xyz;
    float nLen = length(n);
    if (position.w <= 0.0 || !(nLen > 1e-6)) {
        imageStore(outIndirect, pixel, vec4(0.0, 0.0, 0.0, 1.0));
        if ((flags & GATHER_FLAG_AO) != 0u) imageStore(outAo, pixel, vec4(0.0));
        return;
    }
    n /= nLen;
    vec3 albedo = imageLoad(gAlbedo, pixel).rgb;
    vec2 metalRough = imageLoad(gMaterial, pixel).xy;
    ConeTraceParams p = gatherConeParams();
    // Cones leave the surface (x, n): origin offset along n, samples lifted (voxel_cone.glsl)
    ConeSurface surface = ConeSurface(position.xyz, n);
    float offset = gather.specular.z;

    // Diffuse cones (and AO with the same set)
    bool level0Control = (flags & GATHER_FLAG_LEVEL0_RAYS) != 0u;
    uint count = level0Control ? 0u : min(uint(gather.coneInfo.x + 0.5), 16u);
    float tanHalf = gather.coneInfo.y;
    vec3 diffuse = vec3(0.0);
    float visibility = 0.0;
    for (uint i = 0u; i < count; ++i) {
        vec3 dir = coneToWorld(gather.cones[i].xyz, n);
        float w = gather.cones[i].w;
        diffuse += w * traceSurfaceCone(surface, offset, dir, tanHalf, p).rgb;
        if ((flags & GATHER_FLAG_AO) != 0u) {
            visibility +=
                w * traceSurfaceConeVisibility(surface, offset, dir, tanHalf, p.distances.x, p);
        }
    }
    if (level0Control) {
        // The control (issue 43): M cosine-distributed rays (a Hammersley set, rotated per pixel)
        // marched at aperture 0, i.e. through the finest voxels only with the same compositing,
        // step, facing and lift; E = (pi / M) sum L. Not the method.
        uint m = max(gather.sizeFlags.w, 1u);
        uint h = uint(pixel.x) * 1973u + uint(pixel.y) * 9277u + 26699u;
        h = (h ^ (h >> 16)) * 0x7feb352du;
        h = (h ^ (h >> 15)) * 0x846ca68bu;
        vec2 shift = vec2(float(h & 0xffffu), float(h >> 16)) / 65536.0;
        diffuse = vec3(0.0);
        for (uint i = 0u; i < m; ++i) {
            vec2 u = fract(vec2((float(i) + 0.5) / float(m),
                                float(bitfieldReverse(i)) * 2.3283064365386963e-10) + shift);
            float r = sqrt(u.x), phi = 2.0 * BRDF_PI * u.y;
            vec3 local = vec3(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u.x, 0.0)));
            diffuse += traceSurfaceCone(surface, offset, coneToWorld(local, n), 0.0, p).rgb;
        }
        diffuse *= BRDF_PI / float(m);
    }
    vec3 indirect = albedo * (1.0 - metalRough.x) * (1.0 / BRDF_PI) * diffuse;

    // Specular cone along the mirrored view direction
    if ((flags & GATHER_FLAG_SPECULAR) != 0u && brdfIsGlossy(metalRough.x, metalRough.y)) {
        vec3 toEye = gather.cameraPosition.xyz - position.xyz;
        float eyeLen = length(toEye);
        if (eyeLen > 1e-8) {
            vec3 r = reflect(-toEye / eyeLen, n);
            float aperture = specularAperture(metalRough.y);
            vec3 f0 = mix(vec3(0.04), albedo, metalRough.x);
            indirect += f0 * traceSurfaceCone(surface, offset, r, tan(0.5 * aperture), p).rgb;
        }
    }
    // No NaN / Inf leaves the pass
    indirect = clamp(indirect, vec3(0.0), vec3(3.0e38));
    if (any(isnan(indirect))) indirect = vec3(0.0);
    imageStore(outIndirect, pixel, vec4(indirect, 1.0));
    if ((flags & GATHER_FLAG_AO) != 0u) {
        float ao = clamp(visibility / BRDF_PI, 0.0, 1.0);
        imageStore(outAo, pixel, vec4(ao, ao, ao, 1.0));
    }
}
