// Triangle / axis-aligned box overlap by the separating axis theorem (Akenine-Moller 2001):
// 3 box axes, the triangle normal and the 9 edge x axis cross products. Mirrored on the CPU by
// gilab::triangleBoxOverlap (core/voxel/voxel_sat.h). Closed test: touching counts as overlap.
#ifndef GILAB_VOXEL_SAT_GLSL
#define GILAB_VOXEL_SAT_GLSL

bool voxelSatAxisSeparates(vec3 axis, vec3 v0, vec3 v1, vec3 v2, vec3 h) {
    float p0 = dot(axis, v0), p1 = dot(axis, v1), p2 = dot(axis, v2);
    float r = dot(h, abs(axis));
    return min(p0, min(p1, p2)) > r || max(p0, max(p1, p2)) < -r;
}

bool voxelTriangleBoxOverlap(vec3 center, vec3 halfSize, vec3 a, vec3 b, vec3 c) {
    vec3 v0 = a - center, v1 = b - center, v2 = c - center;
    if (any(greaterThan(min(v0, min(v1, v2)), halfSize))) return false;
    if (any(lessThan(max(v0, max(v1, v2)), -halfSize))) return false;
    vec3 e0 = v1 - v0, e1 = v2 - v1, e2 = v0 - v2;
    vec3 n = cross(e0, e1);
    if (abs(dot(n, v0)) > dot(halfSize, abs(n))) return false;
    vec3 edges[3] = vec3[3](e0, e1, e2);
    for (int i = 0; i < 3; ++i) {
        if (voxelSatAxisSeparates(vec3(0.0, -edges[i].z, edges[i].y), v0, v1, v2, halfSize))
            return false;
        if (voxelSatAxisSeparates(vec3(edges[i].z, 0.0, -edges[i].x), v0, v1, v2, halfSize))
            return false;
        if (voxelSatAxisSeparates(vec3(-edges[i].y, edges[i].x, 0.0), v0, v1, v2, halfSize))
            return false;
    }
    return true;
}

#endif  // GILAB_VOXEL_SAT_GLSL
