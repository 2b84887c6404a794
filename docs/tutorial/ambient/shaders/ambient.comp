#version 460
// The tutorial technique (docs/tutorial.md, section 5; ../ambient.cpp): a uniform ambient
// radiance L_a arriving from every direction, unoccluded, reflected by a Lambertian surface:
//   indirect = albedo * L_a
// One thread per pixel. Background pixels have albedo 0 in the G-buffer, so they get 0.
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gAlbedo;      // G-buffer albedo
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D outIndirect;  // the indirect layer

layout(push_constant) uniform Push {
    vec4 ambient;  // rgb = L_a [W/(m^2 sr)]
    uvec4 size;    // x width, y height
} pc;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(pc.size.x) || pixel.y >= int(pc.size.y)) return;
    vec3 albedo = imageLoad(gAlbedo, pixel).rgb;
    imageStore(outIndirect, pixel, vec4(albedo * pc.ambient.rgb, 1.0));
}
