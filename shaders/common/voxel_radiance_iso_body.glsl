// Isotropic radiance filter, one level (core/voxel/voxel_radiance.h). The includer defines
// VOXEL_FORMAT. mode 0 = box (average of the 2x2x2 children); mode 1 = Gaussian: separable
// [1,3,3,1]/8 over the 4^3 fine cells around the 2x2x2 block, the cell-centred analogue of the
// paper's vertex-centred 3^3 tent [1/4,1/2,1/4] (Crassin §4.2.3, notes 001 §2.3). Cells outside
// the grid count as empty. Premultiplied RGBA is filtered linearly.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(set = 0, binding = 0, VOXEL_FORMAT) uniform readonly image3D srcImage;
layout(set = 0, binding = 1, VOXEL_FORMAT) uniform writeonly image3D dstImage;
layout(push_constant) uniform Push {
    uint dstSize;
    uint srcSize;
    uint mode;
    uint pad;
};

vec4 loadCell(ivec3 c) {
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(int(srcSize)))))
        return vec4(0.0);
    return max(imageLoad(srcImage, c), vec4(0.0));
}

void main() {
    ivec3 dst = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(dst, ivec3(int(dstSize))))) return;
    ivec3 src = 2 * dst;
    vec4 sum = vec4(0.0);
    if (mode == 0u) {
        for (int i = 0; i < 8; ++i)
            sum += loadCell(src + ivec3(i & 1, (i >> 1) & 1, i >> 2));
        sum *= 0.125;
    } else {
        const float w[4] = float[4](0.125, 0.375, 0.375, 0.125);
        for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 4; ++y)
                for (int x = 0; x < 4; ++x)
                    sum += (w[x] * w[y] * w[z]) * loadCell(src + ivec3(x, y, z) - 1);
    }
    imageStore(dstImage, dst, sum);
}
