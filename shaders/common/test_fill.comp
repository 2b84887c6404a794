#version 460
// Test shader (tests/vk_test.cpp): writes a known pattern to a storage image and a buffer.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D outImage;
layout(set = 0, binding = 1, std430) writeonly buffer OutBuffer { uint outValues[]; };
layout(push_constant) uniform Push { uint width; uint height; uint seed; };

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= width || p.y >= height) return;
    imageStore(outImage, ivec2(p), vec4(float(p.x), float(p.y), float(p.x * p.y), 0.5));
    outValues[p.y * width + p.x] = p.x * 1000u + p.y + seed;
}
