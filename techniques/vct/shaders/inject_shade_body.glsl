// Voxel shading after the splat (notes 001 §8, dense recommendation): one thread per voxel,
//   E = sum over lights of the light's mean photon irradiance in the voxel (splat_dense_body),
//   base.rgb = a * albedo / pi * E (outgoing diffuse radiance premultiplied by coverage a),
//   base.a = a.
// The paper stores incoming radiance and shades toward each cone at trace time (§7); voxels are
// Lambertian here, so storing the outgoing radiance gives the same diffuse result and drops only
// glossy secondary bounces (techniques/vct/README.md).
#include "inject_common.glsl"

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(set = 0, binding = 3, INJECT_FORMAT) uniform writeonly image3D radianceBase;

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (!voxelInside(pc.grid, c)) return;
    uint index = voxelLinearIndex(pc.grid, c);
#ifdef INJECT_FIXED_POINT
    vec3 irradiance = vec3(irradiancePlanes[0].v[index], irradiancePlanes[1].v[index],
                           irradiancePlanes[2].v[index]) * pc.scale.w;
#else
    vec3 irradiance = vec3(irradiancePlanes[0].v[index], irradiancePlanes[1].v[index],
                           irradiancePlanes[2].v[index]);
#endif
    vec4 albedoOpacity = texelFetch(voxelAlbedoOpacity, c, 0);
    float a = clamp(albedoOpacity.a, 0.0, 1.0);
    vec3 radiance = a * albedoOpacity.rgb * (1.0 / 3.14159265358979) * max(irradiance, vec3(0.0));
    // RGBA16F saturates at 65504: clamp there rather than store Inf (counted in
    // techniques/vct/README.md)
    imageStore(radianceBase, c, vec4(min(radiance, vec3(65504.0)), a));
}
