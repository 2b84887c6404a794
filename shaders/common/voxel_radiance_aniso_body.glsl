// Anisotropic radiance filter, one level (core/voxel/voxel_radiance.h; Crassin §9, notes 003 E5).
// The includer defines VOXEL_FORMAT (rgba16f or rgba32f). One thread per destination voxel writes
// all six faces -X,+X,-Y,+Y,-Z,+Z. For face f along axis a the 2x2x2 children split into 4 pairs
// along a; front = the child a ray travelling toward f enters first (-X: the larger-x child), and
// value = 1/4 sum_pairs [front + (1 - front.a) back] on premultiplied RGBA.
// srcImage = the atlas level l-1 (face f's slab at z + f srcSize), or the base volume
// (SHARED_SOURCE). dstImage = atlas level l (face f's slab at z + f dstSize). From
// the base, each child's colour is first weighted by its facing toward the face's travel
// direction (common/voxel_facing.glsl; surfaceNormals is a zero 1^3 volume when unset).
#include "common/voxel_facing.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(set = 0, binding = 0, VOXEL_FORMAT) uniform readonly image3D srcImage;
layout(set = 0, binding = 1, VOXEL_FORMAT) uniform writeonly image3D dstImage;
layout(push_constant) uniform Push {
    uint dstSize;
    uint srcSize;
    uint mode;  // unused here
    uint pad;
};
layout(set = 0, binding = 2) uniform sampler3D surfaceNormals;
layout(constant_id = 0) const bool SHARED_SOURCE = false;

vec4 children[8];  // index x + 2y + 4z
vec4 childNormals[8];
const vec3 kFaceTravel[6] = vec3[6](vec3(-1, 0, 0), vec3(1, 0, 0), vec3(0, -1, 0), vec3(0, 1, 0),
                                    vec3(0, 0, -1), vec3(0, 0, 1));

// A child's premultiplied value as seen by rays of face f (colour facing-weighted, opacity kept).
vec4 facingChild(int i, int f) {
    if (!SHARED_SOURCE) return children[i];
    return vec4(children[i].rgb * voxelFacing(voxelMeanNormal(childNormals[i]), kFaceTravel[f]),
                children[i].a);
}


vec4 compositeFace(int f) {
    int axis = f / 2;
    bool towardNegative = (f & 1) == 0;  // rays travel toward -axis: enter the larger child first
    int axisBit = 1 << axis;
    vec4 sum = vec4(0.0);
    for (int i = 0; i < 8; ++i) {
        if ((i & axisBit) != 0) continue;  // i = the low child of its pair
        vec4 low = facingChild(i, f), high = facingChild(i | axisBit, f);
        vec4 front = towardNegative ? high : low;
        vec4 back = towardNegative ? low : high;
        sum += front + (1.0 - clamp(front.a, 0.0, 1.0)) * back;
    }
    return 0.25 * sum;
}

// Children of `src` in slab `slab` of the source (slab 0 = the base).
void loadChildren(ivec3 src, int slab) {
    ivec3 offset = ivec3(0, 0, slab * int(srcSize));
    for (int i = 0; i < 8; ++i)
        children[i] = max(imageLoad(srcImage, offset + src + ivec3(i & 1, (i >> 1) & 1, i >> 2)),
                          vec4(0.0));
}

void writeFace(ivec3 src, ivec3 dst, int f) {
    if (!SHARED_SOURCE) loadChildren(src, f);
    imageStore(dstImage, dst + ivec3(0, 0, f * int(dstSize)), compositeFace(f));
}

void main() {
    ivec3 dst = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(dst, ivec3(int(dstSize))))) return;
    ivec3 src = 2 * dst;
    if (SHARED_SOURCE) {
        loadChildren(src, 0);
        bool hasNormals = textureSize(surfaceNormals, 0).x > 1;
        for (int i = 0; i < 8; ++i) {
            ivec3 c = src + ivec3(i & 1, (i >> 1) & 1, i >> 2);
            childNormals[i] = hasNormals ? texelFetch(surfaceNormals, c, 0) : vec4(0.0);
        }
    }
    for (int f = 0; f < 6; ++f)
        writeFace(src, dst, f);
}
