// Photon splat into the octree's leaves (Crassin §8.2, notes 001 §2.5; techniques/vct/svo.md
// "Injection"): the dense path's rule (vct/splat_dense_body.glsl) on the leaf lattice. Launched
// once per light l = pc.args.x with an indirect dispatch over the light's photon range
// (svo_light_ranges.comp), in two modes (pc.args.z):
//   SVO_SPLAT_COUNT: every deposit of the light's photons adds 1 to its sample's count;
//   SVO_SPLAT_IRRADIANCE: every deposit adds E / count (E the photon's irradiance),
// so each leaf sample ends up with this light's mean irradiance over its deposits, summed over
// the lights (the counts are cleared before each light). Exact for a plane at any orientation.
// With float accumulation each deposit weighs its footprint cell's area instead of 1 (the
// area-weighted mean, as the dense splat: vct/splat_dense_body.glsl).
//
// Deposits: the photon's footprint on its tangent plane is cut into kx x ky cells of at most
// v0 / 2 per side; every covered voxel that the plane crosses within a cell's half-diagonal of a
// cell centre gets one deposit (as the dense splat). The footprint comes from the photon alone
// (the octree gets no light views): its area is flux / E (the texel's flux over the irradiance it
// produces, exact for pinhole and orthographic texels), its shape a square of side w = sqrt(A
// cos) across the light direction projected onto the plane: w / cos along the light's tangent
// direction, w across it (the texel's rotation about the ray is not known; the cells overlap
// their neighbours' by the deposit radius, so the union still reaches every crossed voxel).
// Photons with E = 0 (a spot's falloff, back-facing, misses) deposit nothing and count nothing.
//
// Where a deposit goes: voxel s is lattice sample s of the leaves (its centre); it has 1, 2, 4 or
// 8 brick copies, and the canonical one is in leaf cell floor(s / 2) (local index s - 2 floor(s /
// 2) in {0, 1}, a leaf that exists whenever voxel s is covered). Both modes write only that copy,
// so the count read by the irradiance pass is complete without a transfer; afterwards the other
// copies hold 0 and svo_transfer's add / copy passes give every copy the canonical sum.
#include "svo_common.glsl"
#include "photon_footprint.glsl"

layout(set = 2, binding = 0, std430) readonly buffer Photons {
    Photon photons[];
};
layout(local_size_x = SVO_GROUP_SIZE) in;

#define SVO_SPLAT_COUNT 0u
#define SVO_SPLAT_IRRADIANCE 1u


// One-entry cache of the last leaf looked up (a photon's deposits fall in a few leaves).
uvec3 gCell = uvec3(0xFFFFFFFFu);
uint gBrick = SVO_NONE;

// Canonical accumulator index (brick * 27 + local sample) of voxel s if it is covered, else -1.
int coveredSample(ivec3 s) {
    if (any(lessThan(s, ivec3(0))) || any(greaterThanEqual(s, ivec3(svo.dims.x)))) return -1;
    uvec3 cell = uvec3(s >> 1);
    if (cell != gCell) {
        gCell = cell;
        uint node = svoFindNode(cell, svo.dims.y);
        gBrick = node == SVO_NONE ? SVO_NONE : svoWord(node, SVO_W_BRICK);
    }
    if (gBrick == SVO_NONE) return -1;
    ivec3 local = s - 2 * ivec3(cell);
    if (!(imageLoad(svoGeometry, svoBrickOrigin(gBrick) + local).a > 0.0)) return -1;
    return int(gBrick * 27u + uint(svoSampleIndex(local)));
}

void addIrradiance(uint base, vec3 e) {
#ifdef SVO_FLOAT_ACCUM
    for (uint ch = 0u; ch < 3u; ++ch)
        if (e[ch] != 0.0) atomicAdd(svoAccum[base + ch], e[ch]);
#else
    uvec3 q = uvec3(round(e * pc.scale.x));
    for (uint ch = 0u; ch < 3u; ++ch)
        if (q[ch] != 0u) atomicAdd(svoAccum[base + ch], q[ch]);
#endif
}

// Deposits at grid point g (on the tangent plane of normal n) into every covered voxel that the
// plane crosses within rg (grid units, <= 1/2: at most 2 voxels per axis) of g.
void deposit(vec3 g, vec3 n, float rg, vec3 e, bool countMode, float area) {
    ivec3 lo = ivec3(floor(g - rg));
    ivec3 hi = ivec3(floor(g + rg));
    for (int z = lo.z; z <= hi.z; ++z) {
        for (int y = lo.y; y <= hi.y; ++y) {
            for (int x = lo.x; x <= hi.x; ++x) {
                ivec3 c = ivec3(x, y, z);
                if (!footprintTouchesVoxel(c, g, n, rg)) continue;
                int index = coveredSample(c);
                if (index < 0) continue;
#ifdef SVO_FLOAT_ACCUM
                if (countMode) {
                    atomicAdd(svoCount[index], area);
                } else {
                    float total = svoCount[index];
                    if (total > 0.0) addIrradiance(uint(index) * 3u, e * (area / total));
                }
#else
                if (countMode) {
                    atomicAdd(svoCount[index], 1u);
                } else {
                    uint count = svoCount[index];
                    if (count > 0u) addIrradiance(uint(index) * 3u, e / float(count));
                }
#endif
            }
        }
    }
}

void main() {
    uint light = pc.args.x;
    uint base = light * SVO_LIGHT_WORDS;
    uint i = svoLights[base + SVO_LIGHT_FIRST] + svoThread();
    if (i >= svoLights[base + SVO_LIGHT_END]) return;
    Photon p = photons[i];
    if (p.positionValid.w < 0.5 || p.normal.w < 0.5) return;  // miss, or faces away
    if (abs(p.irradiance.w - float(light)) > 0.25) return;   // another light's photon
    vec3 e = max(p.irradiance.rgb, vec3(0.0));
    vec3 flux = max(p.flux.rgb, vec3(0.0));
    float eMax = max(e.r, max(e.g, e.b));
    float fluxMax = max(flux.r, max(flux.g, flux.b));
    if (!(eMax > 0.0) || !(fluxMax > 0.0)) return;
#ifndef SVO_FLOAT_ACCUM
    if (pc.scale.w > 0.0) e = min(e, vec3(pc.scale.w));
#endif
    bool countMode = pc.args.z == SVO_SPLAT_COUNT;
    float v0 = svo.originVoxelSize.w;
    vec3 n = p.normal.xyz;
    vec3 l = p.toLight.xyz;

    // Footprint (world): area A = flux / E; a square of side w across the light direction,
    // projected along it onto the tangent plane
    float area = fluxMax / eMax;
    float cosTheta = clamp(dot(n, l), 1e-3, 1.0);
    vec3 t = l - n * dot(n, l);
    float tl = length(t);
    if (tl > 1e-5) {
        t /= tl;
    } else {
        vec3 guide = abs(n.z) < 0.9 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
        t = normalize(cross(guide, n));
    }
    float w = sqrt(area * cosTheta);
    vec3 ex = t * (w / cosTheta);
    vec3 ey = cross(n, t) * w;

    FootprintCells cells = footprintCells(ex, ey, v0);

    vec3 g0 = (p.positionValid.xyz - svo.originVoxelSize.xyz) / v0;
    float cellArea = footprintCellArea(cells);
    for (int b = 0; b < cells.ky; ++b)
        for (int a = 0; a < cells.kx; ++a)
            deposit(g0 + footprintCellOffset(cells, a, b) / v0, n, cells.radius / v0, e,
                    countMode, cellArea);
}
