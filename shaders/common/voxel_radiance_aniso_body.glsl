// Anisotropic radiance filter, one level (core/voxel/voxel_radiance.h; Crassin §9, notes 003 E5).
// The includer defines VOXEL_FORMAT (rgba16f or rgba32f). One thread per destination voxel writes
// all six faces -X,+X,-Y,+Y,-Z,+Z. For face f along axis a the 2x2x2 children split into 4 pairs
// along a; front = the child a ray travelling toward f enters first (-X: the larger-x child), and
// value = 1/4 sum_pairs [front + (1 - front.a) back] on premultiplied RGBA.
// srcImages[f] = level l-1 of face f, or the base volume in all six slots (SHARED_SOURCE).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(set = 0, binding = 0, VOXEL_FORMAT) uniform readonly image3D srcImages[6];
layout(set = 0, binding = 1, VOXEL_FORMAT) uniform writeonly image3D dstImages[6];
layout(push_constant) uniform Push {
    uint dstSize;
    uint srcSize;
    uint mode;  // unused here
    uint pad;
};
layout(constant_id = 0) const bool SHARED_SOURCE = false;

vec4 children[8];  // index x + 2y + 4z


vec4 compositeFace(int f) {
    int axis = f / 2;
    bool towardNegative = (f & 1) == 0;  // rays travel toward -axis: enter the larger child first
    int axisBit = 1 << axis;
    vec4 sum = vec4(0.0);
    for (int i = 0; i < 8; ++i) {
        if ((i & axisBit) != 0) continue;  // i = the low child of its pair
        vec4 low = children[i], high = children[i | axisBit];
        vec4 front = towardNegative ? high : low;
        vec4 back = towardNegative ? low : high;
        sum += front + (1.0 - clamp(front.a, 0.0, 1.0)) * back;
    }
    return 0.25 * sum;
}

#define LOAD_FROM(F)                                                                  \
    for (int i = 0; i < 8; ++i)                                                       \
        children[i] = max(imageLoad(srcImages[F], src + ivec3(i & 1, (i >> 1) & 1, i >> 2)), \
                          vec4(0.0));

#define FACE(F)                                                        \
    {                                                                  \
        if (!SHARED_SOURCE) { LOAD_FROM(F) }                           \
        imageStore(dstImages[F], dst, compositeFace(F));               \
    }

void main() {
    ivec3 dst = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(dst, ivec3(int(dstSize))))) return;
    ivec3 src = 2 * dst;
    if (SHARED_SOURCE) { LOAD_FROM(0) }
    FACE(0)
    FACE(1)
    FACE(2)
    FACE(3)
    FACE(4)
    FACE(5)
}
