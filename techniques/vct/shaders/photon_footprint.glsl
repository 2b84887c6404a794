// A photon's footprint on its surface's tangent plane, cut into cells for the injection deposits
// (techniques/vct/README.md "Light injection"; shared by the dense splat and the octree splat). The
// footprint is the parallelogram spanned by edges ex, ey (world) around the hit; it is cut into kx
// x ky cells of at most v0 / 2 per side, very long (grazing) footprints clipped at kMaxCellsPerEdge
// cells per edge and kMaxCells in all. `radius` is a cell's half-diagonal, clamped to
// [0.1, 0.5] v0: a deposit reaches every voxel the plane crosses within it.
#ifndef GILAB_VCT_PHOTON_FOOTPRINT_GLSL
#define GILAB_VCT_PHOTON_FOOTPRINT_GLSL

const int kMaxCellsPerEdge = 16;
const int kMaxCells = 64;

struct FootprintCells {
    vec3 ex, ey;  // the (clipped) footprint edges
    int kx, ky;   // cells along each edge
    float radius;
};

FootprintCells footprintCells(vec3 ex, vec3 ey, float v0) {
    float cell = 0.5 * v0;
    float maxEdge = float(kMaxCellsPerEdge) * cell;
    float lx = length(ex), ly = length(ey);
    if (lx > maxEdge) ex *= maxEdge / lx;
    if (ly > maxEdge) ey *= maxEdge / ly;
    int kx = clamp(int(ceil(min(lx, maxEdge) / cell)), 1, kMaxCellsPerEdge);
    int ky = clamp(int(ceil(min(ly, maxEdge) / cell)), 1, kMaxCellsPerEdge);
    while (kx * ky > kMaxCells) {
        if (kx >= ky) kx = (kx + 1) / 2; else ky = (ky + 1) / 2;
    }
    vec3 cx = ex / float(kx), cy = ey / float(ky);
    float r = clamp(0.5 * max(length(cx + cy), length(cx - cy)), 0.1 * v0, 0.5 * v0);
    return FootprintCells(ex, ey, kx, ky, r);
}

// Offset of cell (a, b) from the footprint's centre (world).
vec3 footprintCellOffset(FootprintCells f, int a, int b) {
    return ((float(a) + 0.5) / float(f.kx) - 0.5) * f.ex +
           ((float(b) + 0.5) / float(f.ky) - 0.5) * f.ey;
}

// Area (world) of one cell of the (clipped) footprint: the weight of its deposits.
float footprintCellArea(FootprintCells f) {
    return length(cross(f.ex, f.ey)) / float(f.kx * f.ky);
}

// Whether the tangent plane (normal n) through grid point g crosses voxel c within rg (grid
// units) of g: the deposit rule of both splats.
bool footprintTouchesVoxel(ivec3 c, vec3 g, vec3 n, float rg) {
    float halfExtent = 0.5 * (abs(n.x) + abs(n.y) + abs(n.z)) + 1e-4;
    if (abs(dot(n, vec3(c) + 0.5 - g)) > halfExtent) return false;
    vec3 d = max(max(vec3(c) - g, g - vec3(c + 1)), vec3(0.0));
    return dot(d, d) <= rg * rg;
}

#endif  // GILAB_VCT_PHOTON_FOOTPRINT_GLSL
